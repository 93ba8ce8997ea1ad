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
