"""``indoorsim estimators``, what estimators declare they need, ``--estimator NAME:opts``."""

from __future__ import annotations

import inspect
import re

import numpy as np
import pandas as pd
import pytest

from indoorsim import load_site
from indoorsim.benchmark.evaluation import site_context
from indoorsim.cli import main
from indoorsim.cli.args import CliError, estimator_spec
from indoorsim.estimators.base import (
    NEEDS,
    NotApplicableError,
    SiteContext,
    available,
    estimator_class,
    make,
)
from indoorsim.estimators.nn.inertial import CheckpointError
from indoorsim.scenario.schema import GridSurveySpec, WalkSurveySpec
from indoorsim.world.site import Site

# ---------------------------------------------------------------- the listing


def test_estimators_lists_every_estimator_with_its_needs_and_first_doc_line(capsys):
    assert main(["estimators"]) == 0
    out = capsys.readouterr().out
    table, legend = out.split("\n\n", 1)
    header, *lines = table.splitlines()
    assert re.split(r"\s{2,}", header) == ["name", "needs", "also uses", "what it is"]
    rows = {row[0]: row[1:] for row in (re.split(r"\s{2,}", line) for line in lines)}
    assert list(rows) == available()
    for name, (needs, uses, summary) in rows.items():
        cls = estimator_class(name)
        assert needs == (", ".join(cls.needs) or "nothing")
        assert uses == (", ".join(cls.uses) or "nothing")
        assert summary == inspect.getdoc(cls).splitlines()[0]
    assert rows["han2023-fusion"][0] == "grid survey, training walks"
    assert rows["dr-wifi"][0] == "walk survey, WiFi"
    assert rows["learned-io"][0] == "checkpoint"
    for term, meaning in NEEDS.items():
        assert f"  {term}" in legend and meaning in legend


def test_estimators_name_shows_the_options_it_takes(capsys):
    assert main(["estimators", "chen2022-cpf"]) == 0
    out = capsys.readouterr().out
    assert out.startswith("chen2022-cpf  (indoorsim.estimators.pipelines.chen2022.Chen2022Cpf)")
    assert "needs      walk survey\nalso uses  WiFi, training walks, floor plan\n" in out
    options = {
        row[0]: row[1:]
        for row in (
            re.split(r"\s{2,}", line.strip())
            for line in out.split("options  (")[1].splitlines()[2:]
        )
    }
    assert options["likelihood"] == ["literal", "gaussian | literal"]
    assert options["n_particles"] == ["1000", "int"]
    assert options["survey"] == ["null", "str | None"]
    assert options["dr"] == ["(built)", "GaitDeadReckoning (an object: not settable here)"]
    assert main(["estimators", "nope"]) == 2
    assert "unknown estimator 'nope'; valid estimators are: apf," in capsys.readouterr().err


def test_plugins_without_declared_needs_are_listed_as_such(capsys, monkeypatch):
    class Plain:
        """A plug-in that declares nothing."""

        name = "plain"

    from indoorsim.estimators import base

    monkeypatch.setitem(base._REGISTRY, "plain", Plain)
    assert main(["estimators"]) == 0
    line = next(x for x in capsys.readouterr().out.splitlines() if x.startswith("plain "))
    assert re.split(r"\s{2,}", line) == [
        "plain",
        "not declared",
        "not declared",
        "A plug-in that declares nothing.",
    ]


def test_evaluate_help_lists_the_estimators(capsys):
    assert main(["evaluate", "--help"]) == 0
    text = " ".join(capsys.readouterr().out.split())
    assert f"a registered estimator ({', '.join(available())})" in text


# --------------------------------------------------- the declared needs are honest


@pytest.mark.parametrize("name", available())
def test_every_registered_estimator_declares_needs_in_the_documented_terms(name):
    cls = estimator_class(name)
    assert isinstance(cls.needs, tuple) and isinstance(cls.uses, tuple)
    assert set(cls.needs) | set(cls.uses) <= set(NEEDS)
    assert not set(cls.needs) & set(cls.uses)


@pytest.fixture(scope="module")
def contexts() -> dict[str, SiteContext]:
    """The minimal room's public knowledge with a grid and a walk survey, and parts of it."""
    base = load_site("minimal_room").scenario
    surveys = {
        "grid": GridSurveySpec(kind="grid", spacing=2.0, duration_s=2.0),
        "walk": WalkSurveySpec(kind="walk", route="main", reference_spacing=3.0, wifi_dwell_s=3.0),
    }
    full = site_context(
        Site(base.model_copy(update={"surveys": surveys})), device="ideal", survey_device="ideal"
    )

    def only(name: str, drop_table: str = "") -> SiteContext:
        db = full.fingerprints[name].copy()
        db.tables.pop(drop_table, None)
        return SiteContext(**{**vars(full), "fingerprints": {name: db}})

    return {
        "bare": SiteContext(name="bare"),
        "grid only": only("grid"),
        "walk only": only("walk"),
        "walk without WiFi": only("walk", drop_table="wifi"),
    }


def _fit(name: str, ctx: SiteContext) -> Exception | None:
    # Han2023's networks on small budgets: what is checked is whether fit may run at all.
    small = {"population": 4, "iterations": 2, "epochs": 2}
    cls = estimator_class(name)
    options = {k: v for k, v in small.items() if k in inspect.signature(cls).parameters}
    try:
        make(name, **options).fit(ctx, [])
    except NotApplicableError as err:
        return err
    return None


@pytest.mark.parametrize("name", available())
def test_what_an_estimator_declares_it_needs_is_what_its_fit_refuses_without(name, contexts):
    needs = set(estimator_class(name).needs)
    # No survey, no training walk, no plan: only estimators that need none of them run.
    refused = _fit(name, contexts["bare"])
    assert (refused is not None) == bool(needs - {"checkpoint"}), refused
    if "grid survey" in needs:
        assert _fit(name, contexts["walk only"]) is not None
    if "walk survey" in needs:
        assert _fit(name, contexts["grid only"]) is not None
        without_wifi = _fit(name, contexts["walk without WiFi"])
        assert (without_wifi is not None) == ("WiFi" in needs), without_wifi
    if needs == {"grid survey", "training walks"}:  # han2023-fusion: the survey alone is not enough
        assert "training walks" in str(_fit(name, contexts["grid only"]))
    if "checkpoint" in needs:
        with pytest.raises(CheckpointError):
            make(name, checkpoint="/nonexistent/checkpoint").fit(contexts["bare"], [])


# ------------------------------------------------------- --estimator NAME:options


@pytest.mark.parametrize(
    ("text", "expected"),
    [
        ("pdr-basic", ("pdr-basic", {})),
        (
            "chen2022-cpf:likelihood=gaussian,n_particles=500",
            ("chen2022-cpf", {"likelihood": "gaussian", "n_particles": 500}),
        ),
        (
            'x:a=true,b=null,c=1e-3,d="7",e=[1, 2],f=some/path,g',
            ("x", {"a": True, "b": None, "c": 0.001, "d": "7", "e": [1, 2], "f": "some/path,g"}),
        ),
        ("learned-io:checkpoint=path/to/io", ("learned-io", {"checkpoint": "path/to/io"})),
        ("my_pkg.mod:Class", ("my_pkg.mod:Class", {})),
        ("my_pkg.mod:Class:k=3", ("my_pkg.mod:Class", {"k": 3})),
    ],
)
def test_estimator_spec_reads_options_as_json_or_plain_strings(text, expected):
    assert estimator_spec(text) == expected


@pytest.mark.parametrize(
    ("text", "message"),
    [
        ("x=1", "--estimator x=1: expected NAME:key=value,..."),
        ("x:k=1,k=2", "--estimator x: option k given twice"),
    ],
)
def test_estimator_spec_refuses_what_is_not_an_option_list(text, message):
    with pytest.raises(CliError, match=re.escape(message)):
        estimator_spec(text)


EVALUATE = ["evaluate", "--scenario", "minimal_room", "--seeds", "1", "--device", "ideal"]


@pytest.mark.parametrize(
    ("spec", "message"),
    [
        (
            "chen2022-cpf:likelihod=gaussian",
            "--estimator chen2022-cpf: unknown option 'likelihod'; its options are: query_steps, ",
        ),
        (
            "chen2022-cpf:likelihood=normal",
            "--estimator chen2022-cpf: option likelihood=normal: expected one of gaussian, literal",
        ),
        (
            "chen2022-cpf:n_particles=many",
            "--estimator chen2022-cpf: option n_particles=many: expected a whole number",
        ),
        (
            "chen2022-cpf:calibrate=False",
            "--estimator chen2022-cpf: option calibrate=False: expected true or false",
        ),
        (
            "chen2022-cpf:dr={}",
            "--estimator chen2022-cpf: option dr={}: expected a GaitDeadReckoning (not settable",
        ),
        (  # the constructor's own ValueError, with the option that causes it
            "chen2022-cpf:query_steps=0",
            "--estimator chen2022-cpf: option query_steps=0: need query_steps ≥ 1",
        ),
        (
            "chen2022-cpf:use_magnetic=false,use_wifi=false",
            "--estimator chen2022-cpf: options use_magnetic=false, use_wifi=false together: "
            "use_magnetic and use_wifi cannot both be False",
        ),
        ("start-only:k=1", "--estimator start-only: unknown option 'k'; its options are: none"),
        ("nope:k=1", "--estimator: unknown estimator 'nope'; valid estimators are: apf,"),
    ],
)
def test_bad_estimator_options_are_refused_in_one_line_naming_estimator_and_option(
    tmp_path, capsys, spec, message
):
    out = tmp_path / "out"
    assert main([*EVALUATE, "--estimator", spec, "--out", str(out)]) == 2
    err = capsys.readouterr().err
    assert err.startswith(f"indoorsim: {message}") and err.count("\n") == 1, err
    assert not out.exists()


def test_estimator_options_reach_the_constructor_on_both_paths(tmp_path, walk_folder, capsys):
    spec = "pdr-basic:weinberg_k=0.6"
    assert main([*EVALUATE, "--estimator", spec, "--out", str(tmp_path / "sim")]) == 0
    summary = pd.read_csv(tmp_path / "sim" / "summary.csv")
    assert (summary["estimator"].iloc[0], summary["params"].iloc[0]) == (
        "pdr-basic",
        '{"weinberg_k": 0.6}',
    )
    default = ["evaluate", "--recording", str(walk_folder), "--estimator"]
    assert main([*default, "pdr-basic", "--out", str(tmp_path / "k48")]) == 0
    assert main([*default, spec, "--out", str(tmp_path / "k60")]) == 0
    k48, k60 = (pd.read_csv(tmp_path / k / "summary.csv") for k in ("k48", "k60"))
    assert k60["params"].iloc[0] == '{"weinberg_k": 0.6}' and k48["params"].iloc[0] == "{}"
    # Weinberg's length is K times the same function of the steps: every move is 0.6/0.48 as long.
    moves = []
    for k in ("k48", "k60"):
        xy = pd.read_csv(tmp_path / k / "estimates.csv")[["x", "y"]].to_numpy()
        moves.append(xy - xy[0])
    assert abs(moves[0]).max() > 0.5
    np.testing.assert_allclose(moves[1], moves[0] * 0.6 / 0.48, rtol=1e-9, atol=1e-12)


def test_a_checkpoint_that_is_not_there_is_one_line_naming_the_option(tmp_path, capsys):
    spec = f"learned-io:checkpoint={tmp_path / 'missing'}"
    assert main([*EVALUATE, "--estimator", spec, "--out", str(tmp_path / "out")]) == 2
    route, err = capsys.readouterr().err.splitlines()
    assert route == "route: main (the only one)"
    assert err == (
        f"indoorsim: --estimator learned-io: option checkpoint: {tmp_path / 'missing'}: "
        "no model.json: not an inertial-odometry checkpoint folder"
    )
    assert not (tmp_path / "out").exists()
