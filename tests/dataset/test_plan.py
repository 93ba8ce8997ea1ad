"""The data-set plan: per-stretch carrying-mode parameters, drawn or fixed by the config."""

from __future__ import annotations

import pytest
import yaml

from indoorsim.dataset import DatasetConfig, DatasetConfigError, make_plan
from indoorsim.phone.devices import device_to_dict, get_device

BASE = {"sites": 2, "walks_per_site": 3, "bundled_share": 0.0, "mode_changes_per_minute": 2.0}


def _plan(**overrides):
    return make_plan(DatasetConfig(**(BASE | overrides)).resolved())


def test_held_phones_draw_their_screen_tilt_per_stretch_by_default():
    tilts = [
        entry[2]["pitch_deg"]
        for walk in _plan().walks
        for entry in walk.modes
        if entry[1] == "handheld"
    ]
    assert tilts and all(0.0 <= t <= 45.0 for t in tilts)
    assert len(set(tilts)) == len(tilts)
    other = [entry for walk in _plan().walks for entry in walk.modes if entry[1] != "handheld"]
    assert all(len(entry) == 2 for entry in other)


def test_a_config_fixes_a_mode_parameter_without_moving_any_other_draw():
    drawn, fixed = _plan(), _plan(mode_params={"pocketed": {"side": "left"}, "handheld": {}})
    for a, b in zip(drawn.walks, fixed.walks, strict=True):
        assert (a.device, a.walker, a.seed, a.route_seed) == (
            b.device,
            b.walker,
            b.seed,
            b.route_seed,
        )
        assert [e[:2] for e in a.modes] == [e[:2] for e in b.modes]
        for entry in b.modes:
            assert entry[2:] == ([{"side": "left"}] if entry[1] == "pocketed" else [])
        assert b.schedule.entries[0].mode == b.modes[0][1]


@pytest.mark.parametrize(
    ("mode_params", "message"),
    [
        ({"juggling": {}}, "mode_params.juggling: unknown carrying mode 'juggling'"),
        ({"handheld": {"colour": 1.0}}, "mode_params.handheld.colour: not a parameter of"),
    ],
)
def test_unknown_modes_and_parameters_are_named_by_key(mode_params, message):
    with pytest.raises(DatasetConfigError, match=message):
        DatasetConfig(**(BASE | {"mode_params": mode_params})).resolved()


def test_a_device_file_is_drawn_like_a_named_profile_and_a_broken_one_is_named(tmp_path):
    twin = tmp_path / "twin.yaml"
    twin.write_text(
        yaml.safe_dump({"device": device_to_dict(get_device("honor_50")) | {"name": "twin"}})
    )
    plan = _plan(devices=[str(twin)])
    assert {walk.device for walk in plan.walks} == {str(twin)}
    broken = tmp_path / "broken.yaml"
    broken.write_text("name: b\naccel: {rate_hz: 0}\n")
    with pytest.raises(DatasetConfigError, match=r"devices\[1\]: .*rate_hz must be > 0"):
        _plan(devices=[str(twin), str(broken)])


def test_a_scenario_file_is_a_site_like_a_bundled_one_and_a_broken_one_is_named(tmp_path):
    """An imported real floor (or any scenario file) joins the data set as a site."""
    from indoorsim.dataset.shard import _site, simulate_walk
    from indoorsim.scenario.load import resolve_scenario

    plan_file = tmp_path / "imported.yaml"
    plan_file.write_text(resolve_scenario("minimal_room").read_text())
    config = DatasetConfig(
        **(BASE | {"bundled": [str(plan_file)], "bundled_share": 0.5, "minutes": 0.2})
    ).resolved()
    plan = make_plan(config)
    first = plan.sites[0]
    assert (first.id, first.source, first.kind) == (str(plan_file), "file", "file")
    assert plan.sites[1].source == "generated"
    walk = next(w for w in plan.walks if w.site == 0)
    rec = simulate_walk(_site(first), walk, config)
    assert rec.duration > 10.0
    broken = tmp_path / "broken.yaml"
    broken.write_text("name: b\nwalls: [\n")
    with pytest.raises(DatasetConfigError, match=r"bundled\[1\]: .*broken.yaml"):
        DatasetConfig(**(BASE | {"bundled": [str(plan_file), str(broken)]})).resolved()


def test_a_resumed_data_set_refuses_a_scenario_file_that_changed(tmp_path):
    """The folder keeps each input file's checksum: a resumed run would otherwise mix two
    buildings under one name."""
    from indoorsim.dataset.driver import INPUTS_FILE, DatasetFolderError, prepare_folder
    from indoorsim.scenario.load import resolve_scenario

    plan_file = tmp_path / "imported.yaml"
    plan_file.write_text(resolve_scenario("minimal_room").read_text())
    config = DatasetConfig(
        **(BASE | {"bundled": [str(plan_file)], "bundled_share": 0.5})
    ).resolved()
    out = tmp_path / "data"
    prepare_folder(out, config)
    assert (out / INPUTS_FILE).is_file()
    prepare_folder(out, config)  # the same file: the run resumes
    plan_file.write_text(plan_file.read_text().replace("minimal", "minimal-edited", 1))
    with pytest.raises(DatasetFolderError, match=r"(?s)input file changed.*imported\.yaml: sha256"):
        prepare_folder(out, config)
    # A data set of built-in names and the ordinary vigour writes no such file.
    plain = tmp_path / "plain"
    prepare_folder(plain, DatasetConfig(**BASE, walker={"vigour": "default"}).resolved())
    assert not (plain / INPUTS_FILE).exists()


def test_the_real_walkers_table_is_an_input_file_and_an_older_folder_resumes_as_made(
    tmp_path, monkeypatch
):
    """The plan reads the real walkers' table, so the folder keeps its checksum; a data set
    started before walkers took real vigour was made without it, and resumes so."""
    import json

    from indoorsim.dataset import driver
    from indoorsim.dataset.driver import INPUTS_FILE, DatasetFolderError, prepare_folder
    from indoorsim.walker.real_walkers import load_real_walkers

    out = tmp_path / "data"
    prepare_folder(out, DatasetConfig(**BASE).resolved())
    stored = json.loads((out / INPUTS_FILE).read_text())
    assert list(stored) == [driver.REAL_WALKERS_INPUT]
    # A refreshed table would mix two populations of walkers in one data set.
    table = tmp_path / "walkers.csv"
    load_real_walkers().iloc[:3].to_csv(table, index=False)
    monkeypatch.setattr(driver, "REAL_WALKERS_CSV", table)
    with pytest.raises(DatasetFolderError, match=r"real_walkers\.csv: sha256"):
        prepare_folder(out, DatasetConfig(**BASE).resolved())
    # A folder from before the setting: its config has no walker.vigour.
    old = tmp_path / "old"
    config = DatasetConfig(**BASE, walker={"vigour": "default"}).resolved()
    prepare_folder(old, config)
    saved = json.loads((old / "config.json").read_text())
    del saved["walker"]["vigour"]
    (old / "config.json").write_text(json.dumps(saved))
    prepare_folder(old, config)  # resumes as it was made
    with pytest.raises(DatasetFolderError, match=r'walker\.vigour: stored "default"'):
        prepare_folder(old, DatasetConfig(**BASE).resolved())


def test_each_walk_takes_one_real_walkers_vigour_by_default_and_nothing_else_moves():
    from indoorsim.walker.real_walkers import VIGOUR_FIELDS, load_real_walkers

    rows = {tuple(r) for r in load_real_walkers()[list(VIGOUR_FIELDS)].itertuples(index=False)}
    real, plain = _plan(sites=4), _plan(sites=4, walker={"vigour": "default"})
    drawn = [tuple(w.walker[name] for name in VIGOUR_FIELDS) for w in real.walks]
    assert set(drawn) <= rows and len(set(drawn)) > 1
    for a, b in zip(real.walks, plain.walks, strict=True):
        assert not set(VIGOUR_FIELDS) & set(b.walker)
        assert {k: v for k, v in a.walker.items() if k not in VIGOUR_FIELDS} == b.walker
        assert (a.device, a.modes, a.seed, a.route_seed) == (
            b.device,
            b.modes,
            b.seed,
            b.route_seed,
        )


def test_walkers_slow_at_route_points_only_where_the_config_says_and_nothing_else_moves(
    tmp_path,
):
    import json

    from indoorsim.dataset.driver import prepare_folder
    from indoorsim.walker.gait import WalkerParams

    slowing, plain = _plan(walker={"mark_speed": {"low": 0.2, "high": 0.9}}), _plan()
    for a, b in zip(slowing.walks, plain.walks, strict=True):
        assert "mark_speed" not in b.walker
        assert a.walker.pop("mark_speed") == [0.2, 0.9]  # a range, drawn per route point
        assert (a.walker, a.device, a.modes, a.seed, a.route_seed) == (
            b.walker,
            b.device,
            b.modes,
            b.seed,
            b.route_seed,
        )
    assert WalkerParams(mark_speed=[0.2, 0.9]).mark_speed == (0.2, 0.9)
    with pytest.raises(ValueError, match="mark_speed"):
        DatasetConfig(**BASE, walker={"mark_speed": {"low": 0.0, "high": 0.5}})
    # A folder from before the setting (its config has no walker.mark_speed) resumes.
    old, config = tmp_path / "old", DatasetConfig(**BASE).resolved()
    prepare_folder(old, config)
    saved = json.loads((old / "config.json").read_text())
    del saved["walker"]["mark_speed"]
    (old / "config.json").write_text(json.dumps(saved))
    prepare_folder(old, config)
