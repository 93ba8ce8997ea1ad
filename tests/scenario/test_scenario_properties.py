"""Property tests of scenario files: random valid sites round-trip and simulate; random
damage to a valid file always gets the loader's one clear error, never a traceback.

Valid scenarios are small rectangular rooms and corridors with lights, dipoles, access
points and a route, drawn inside the schema's limits. Invalid ones are a valid file
(every key written out, defaults too) with one thing broken: a value of the wrong type,
NaN or ±inf, a number far out of range, a key deleted or given twice, a byte that is not
UTF-8, or the text cut short.
"""

from __future__ import annotations

import contextlib
import datetime
import io
import itertools
import math
import re
import warnings
from pathlib import Path
from typing import Any

import numpy as np
import pytest
import yaml
from hypothesis import example, given, settings
from hypothesis import strategies as st

from indoorsim.cli import main
from indoorsim.scenario import (
    Scenario,
    ScenarioError,
    dump_scenario,
    load_scenario,
    parse_scenario,
    scenario_to_dict,
)
from indoorsim.simulate import simulate
from indoorsim.world.site import Site
from tests.conftest import BUNDLED_MINIMAL, SWEEP

# ---------------------------------------------------------------- valid scenarios

MATERIALS = ("concrete", "brick", "drywall", "glass", "wood", "metal", "metal_door")
MARGIN_M = 0.4  # route and lights keep this far from a wall's face


def _finite(lo: float, hi: float) -> st.SearchStrategy[float]:
    return st.floats(lo, hi, allow_nan=False, allow_infinity=False)


@st.composite
def rooms(draw: st.DrawFn) -> dict[str, Any]:
    """A closed rectangular room or corridor with its contents, as a scenario mapping."""
    if draw(st.booleans()):
        width, depth = draw(_finite(2.0, 30.0)), draw(_finite(2.0, 15.0))
    else:  # a corridor
        width, depth = draw(_finite(8.0, 40.0)), draw(_finite(1.6, 3.0))
    thickness = draw(_finite(0.05, 0.4))
    corners = [(0.0, 0.0), (width, 0.0), (width, depth), (0.0, depth)]
    walls = [
        {
            "from": list(corners[i]),
            "to": list(corners[(i + 1) % 4]),
            "thickness": thickness,
            "material": draw(st.sampled_from(MATERIALS)),
        }
        for i in range(4)
    ]
    inner = thickness / 2 + MARGIN_M
    xs, ys = _finite(inner, width - inner), _finite(inner, depth - inner)
    ceiling = draw(_finite(2.2, 5.0))
    luminaires = [
        {
            "position": [draw(xs), draw(ys), draw(_finite(0.5, ceiling))],
            "intensity_cd": draw(_finite(0.0, 3000.0)),
            "exponent": draw(_finite(0.0, 5.0)),
        }
        for _ in range(draw(st.integers(0, 3)))
    ]
    # Dipoles may sit outside the room (steel in the next room, the slab below).
    moments = _finite(-5000.0, 5000.0)  # |moment| ≤ 8660 A·m², within the schema's 1e4
    dipoles = [
        {
            "position": [draw(_finite(-20, 60)), draw(_finite(-20, 30)), draw(_finite(-3, 6))],
            "moment": [draw(moments), draw(moments), draw(moments)],
        }
        for _ in range(draw(st.integers(0, 3)))
    ]
    wifi = [
        {
            "bssid": f"02:00:00:00:00:{i + 1:02x}",
            "position": [draw(xs), draw(ys), draw(_finite(0.0, ceiling))],
            "tx_power_dbm": draw(_finite(-10.0, 36.0)),
            "frequency_ghz": draw(st.sampled_from([2.412, 2.437, 5.18, 5.5, 5.745])),
        }
        for i in range(draw(st.integers(0, 3)))
    ]
    # Legs of at least a metre: a walk, not a shuffle on the spot.
    waypoints = draw(
        st.lists(st.tuples(xs, ys), min_size=2, max_size=4).filter(
            lambda pts: all(math.dist(a, b) >= 1.0 for a, b in itertools.pairwise(pts))
        )
    )
    return {
        "name": draw(st.from_regex(r"[a-z][a-z0-9_-]{0,15}", fullmatch=True)),
        "seed": draw(st.integers(0, 2**31)),
        "site": {
            "latitude": draw(_finite(-80.0, 80.0)),
            "longitude": draw(_finite(-180.0, 180.0)),
            "date": draw(
                st.dates(datetime.date(1950, 1, 1), datetime.date(2029, 12, 31))
            ).isoformat(),
            "north_deg": draw(_finite(-360.0, 360.0)),
            "ceiling_height": ceiling,
        },
        "walls": walls,
        "luminaires": luminaires,
        "magnetic": {"dipoles": dipoles},
        "wifi": wifi,
        "routes": {
            "walk": {"waypoints": [list(p) for p in waypoints], "speed": draw(_finite(0.5, 2.0))}
        },
    }


def _round_trips(data: dict[str, Any], folder: Path) -> Scenario:
    scenario = parse_scenario(data)
    path = folder / "site.yaml"
    text = dump_scenario(scenario, path)
    again = load_scenario(path)
    assert again == scenario
    assert dump_scenario(again) == text  # the file is a fixed point too
    return scenario


@given(data=rooms())
def test_random_valid_scenarios_round_trip_through_yaml(tmp_path_factory, data):
    _round_trips(data, tmp_path_factory.mktemp("round_trip"))


@pytest.mark.slow
@settings(SWEEP)
@given(data=rooms())
def test_random_valid_scenarios_round_trip_sweep(tmp_path_factory, data):
    _round_trips(data, tmp_path_factory.mktemp("round_trip"))


def _walks(data: dict[str, Any]) -> None:
    scenario = parse_scenario(data)
    rec = simulate(Site(scenario), route="walk", device="ideal", seed=1, duration_s=2.0)
    rec.validate()
    for name in ("accel", "gyro", "mag", "light"):
        assert np.isfinite(rec.streams[name].to_numpy()).all(), name
    # The walker stays on the floor: inside the walls' inner faces.
    width, depth = data["walls"][1]["from"][0], data["walls"][2]["from"][1]
    half = data["walls"][0]["thickness"] / 2
    x, y = rec.truth["x"].to_numpy(), rec.truth["y"].to_numpy()
    assert (half < x).all() and (x < width - half).all()
    assert (half < y).all() and (y < depth - half).all()


# Each walk costs a site build and a fraction of a second of simulation.
@settings(max_examples=15)
@given(data=rooms())
def test_random_valid_scenarios_simulate_a_short_walk(data):
    _walks(data)


@pytest.mark.slow
@settings(SWEEP, max_examples=100)
@given(data=rooms())
def test_random_valid_scenarios_simulate_sweep(data):
    _walks(data)


# ---------------------------------------------------------------- damaged files

# Every key written out (defaults too), so that damage can reach every key of the schema.
BASE = scenario_to_dict(load_scenario(BUNDLED_MINIMAL))

Path_ = tuple[str | int, ...]

REQUIRED = {
    "name",
    "site",
    "site.latitude",
    "site.longitude",
    "site.date",
    "site.ceiling_height",
    "walls",
    "walls[].from",
    "walls[].to",
    "walls[].thickness",
    "luminaires[].position",
    "luminaires[].intensity_cd",
    "magnetic.dipoles[].position",
    "magnetic.dipoles[].moment",
    "wifi[].bssid",
    "wifi[].position",
}
"""Keys of the base file without a default, with list indices as ``[]``."""


def _dotted(path: Path_) -> str:
    out = ""
    for part in path:
        out += f"[{part}]" if isinstance(part, int) else (f".{part}" if out else part)
    return out


def _nodes(tree: Any, path: Path_ = ()) -> list[Path_]:
    """Every key path of ``tree`` below the root."""
    out = [path] if path else []
    if isinstance(tree, dict):
        for key, value in tree.items():
            out += _nodes(value, (*path, key))
    elif isinstance(tree, list):
        for i, value in enumerate(tree):
            out += _nodes(value, (*path, i))
    return out


def _replace(tree: Any, path: Path_, value: Any) -> Any:
    if not path:
        return value
    head, rest = path[0], path[1:]
    if isinstance(tree, dict):
        return {k: (_replace(v, rest, value) if k == head else v) for k, v in tree.items()}
    return [(_replace(v, rest, value) if i == head else v) for i, v in enumerate(tree)]


def _delete(tree: Any, path: Path_) -> Any:
    head, rest = path[0], path[1:]
    if not rest:
        if isinstance(tree, dict):
            return {k: v for k, v in tree.items() if k != head}
        return [v for i, v in enumerate(tree) if i != head]
    if isinstance(tree, dict):
        return {k: (_delete(v, rest) if k == head else v) for k, v in tree.items()}
    return [(_delete(v, rest) if i == head else v) for i, v in enumerate(tree)]


def _get(tree: Any, path: Path_) -> Any:
    for part in path:
        tree = tree[part]
    return tree


def _is_number(value: Any) -> bool:
    return isinstance(value, int | float) and not isinstance(value, bool)


NODES = _nodes(BASE)
NUMBERS = [p for p in NODES if _is_number(_get(BASE, p))]


def _yaml(tree: Any) -> bytes:
    return yaml.safe_dump(tree, sort_keys=False, allow_unicode=True).encode("utf-8")


@st.composite
def surely_invalid(draw: st.DrawFn) -> tuple[bytes, str, str]:
    """A damaged file that no loader may accept, the key path its error must name and
    words its message must hold.

    The key path is where the damage is, or a key holding it (a check of a whole
    wall or route reports there); "" where the words say where instead (the lines of
    a key given twice, the byte that is not UTF-8).
    """
    kind = draw(
        st.sampled_from(["wrong type", "not finite", "missing key", "duplicate key", "bytes"])
    )
    if kind == "wrong type":
        path = draw(st.sampled_from(NODES))
        old = _get(BASE, path)
        # Values no lax conversion turns into the old one's type: a mapping for a
        # scalar, a word for a list, a mapping or a number.
        new = "not-a-value" if isinstance(old, dict | list) or old is None else {"x": [1]}
        return _yaml(_replace(BASE, path, new)), _dotted(path), ""
    if kind == "not finite":
        path = draw(st.sampled_from(NUMBERS))
        new = draw(st.sampled_from([math.nan, math.inf, -math.inf]))
        return _yaml(_replace(BASE, path, new)), _dotted(path), ""
    if kind == "missing key":
        required = [p for p in NODES if re.sub(r"\[\d+\]", "[]", _dotted(p)) in REQUIRED]
        path = draw(st.sampled_from(required))
        return _yaml(_delete(BASE, path)), _dotted(path), "Field required"
    if kind == "duplicate key":
        # Block-style YAML: a copy of a "key: value" line right after it is the same
        # key again in the same mapping ("- key:" starts a list item: its copy drops
        # the dash).
        lines = _yaml(BASE).decode().splitlines(keepends=True)
        keyed = [i for i, line in enumerate(lines) if re.match(r"\s*(- )?[\w]+:", line)]
        i = draw(st.sampled_from(keyed))
        line = lines[i]
        again = re.sub(r"^(\s*)- ", r"\1  ", line)
        if line.rstrip().endswith(":"):  # a nested block: the copy holds it again
            indent = len(line) - len(line.lstrip(" -"))
            end = i + 1
            while end < len(lines) and len(lines[end]) - len(lines[end].lstrip(" -")) > indent:
                end += 1
            block = [again, *lines[i + 1 : end]]
        else:
            end, block = i + 1, [again]
        key = re.match(r"\s*(- )?(\w+):", line).group(2)
        text = "".join([*lines[:end], *block, *lines[end:]])
        return text.encode("utf-8"), "", f"duplicate key {key!r} at line {end + 1} (first"
    # bytes that are never UTF-8 (a lone continuation byte, a byte UTF-8 never uses)
    text = _yaml(BASE)
    at = draw(st.integers(0, len(text)))
    bad = draw(st.sampled_from([b"\x80", b"\xff", b"\xc3", b"\xe9 ", b"\xfe\xff"]))
    return text[:at] + bad + text[at:], "", "not UTF-8 text: byte 0x"


@st.composite
def any_damage(draw: st.DrawFn) -> bytes:
    """A file damaged in ways that may or may not leave it valid."""
    kind = draw(st.sampled_from(["out of range", "delete", "truncate", "insert bytes"]))
    if kind == "out of range":
        path = draw(st.sampled_from(NUMBERS))
        new = draw(
            st.sampled_from([1e300, -1e300, 1e9, -1e9, -1.0, 0.0, 2**63, -(2**63)])
            | st.floats(allow_nan=False, allow_infinity=False)
            | st.integers()
        )
        return _yaml(_replace(BASE, path, new))
    if kind == "delete":
        return _yaml(_delete(BASE, draw(st.sampled_from(NODES))))
    text = _yaml(BASE)
    if kind == "truncate":
        return text[: draw(st.integers(0, len(text)))]
    at = draw(st.integers(0, len(text)))
    return text[:at] + draw(st.binary(min_size=1, max_size=8)) + text[at:]


def _load_error(folder: Path, content: bytes) -> ScenarioError | None:
    """Load ``content`` from a file: None if it is a valid scenario, else its ScenarioError.

    Any other exception escapes, and fails the test.
    """
    path = folder / "site.yaml"
    path.write_bytes(content)
    try:
        load_scenario(path)
    except ScenarioError as err:
        assert err.source == str(path)
        assert str(path) in str(err)
        assert err.problems and all(message for _, message in err.problems)
        return err
    return None


def _check_refused(folder: Path, content: bytes, key: str, words: str) -> None:
    """``content`` is refused, naming ``key`` (or a key holding it) with ``words``."""
    err = _load_error(folder, content)
    assert err is not None, content.decode(errors="replace")
    named = [
        message
        for path, message in err.problems
        if not key or key == path or key.startswith((f"{path}.", f"{path}["))
    ]
    assert any(words in message for message in named), (key, words, err.problems)


@given(case=surely_invalid())
@example(
    case=(
        _yaml(_replace(BASE, ("walls", 0, "to", 0), 1e9)),
        "walls[0].to[0]",
        "beyond the coordinate limit",
    )
)
def test_a_damaged_file_is_one_clear_error_naming_file_and_key(tmp_path_factory, case):
    _check_refused(tmp_path_factory.mktemp("damaged"), *case)


@given(content=any_damage())
def test_any_damage_loads_or_is_a_clear_error(tmp_path_factory, content):
    _load_error(tmp_path_factory.mktemp("damaged"), content)


@pytest.mark.slow
@settings(SWEEP)
@given(content=any_damage())
def test_any_damage_loads_or_is_a_clear_error_sweep(tmp_path_factory, content):
    _load_error(tmp_path_factory.mktemp("damaged"), content)


@pytest.mark.slow
@settings(SWEEP)
@given(case=surely_invalid())
def test_a_damaged_file_is_one_clear_error_sweep(tmp_path_factory, case):
    _check_refused(tmp_path_factory.mktemp("damaged"), *case)


CLI_ARGS = ["--mode", "handheld", "--device", "ideal", "--seed", "1"]
EXTREMES = [1e300, -1e300, 1e9, -1e9, 1e5, -1.0, 0.0, 1e-300, 2**63]


@st.composite
def extreme_numbers(draw: st.DrawFn) -> bytes:
    """The base file with one number replaced by one far out of its usual range."""
    path = draw(st.sampled_from(NUMBERS))
    return _yaml(_replace(BASE, path, draw(st.sampled_from(EXTREMES))))


def _refused_or_walks(folder: Path, content: bytes) -> None:
    """A value the schema lets through must not break the simulation further on."""
    if _load_error(folder, content) is None:
        site = Site(load_scenario(folder / "site.yaml"))
        with warnings.catch_warnings():
            # NaN or overflow anywhere on the way is a defect too, not only an exception.
            warnings.simplefilter("error", RuntimeWarning)
            rec = simulate(site, route="main", device="ideal", seed=1, duration_s=2.0)
        rec.validate()


# Found by hypothesis, each once a traceback deep in the world model: a light's
# direction of 1e300 (NaN after normalising), a K-factor of 1e300 dB (OverflowError),
# a shadowing correlation of 1e9 m or 1e-300 m (ValueError, OverflowError).
@settings(max_examples=20)
@given(content=extreme_numbers())
@example(content=_yaml(_replace(BASE, ("luminaires", 0, "along", 1), 1e300)))
@example(content=_yaml(_replace(BASE, ("luminaires", 0, "axis", 2), -1e300)))
@example(content=_yaml(_replace(BASE, ("radio", "multipath", "rician_k_db"), 1e300)))
@example(content=_yaml(_replace(BASE, ("radio", "multipath", "rician_k_sigma_db"), 1e5)))
@example(content=_yaml(_replace(BASE, ("radio", "shadowing_correlation_m"), 1e9)))
@example(content=_yaml(_replace(BASE, ("radio", "shadowing_correlation_m"), 1e-300)))
def test_a_far_out_value_is_refused_or_simulates(tmp_path_factory, content):
    _refused_or_walks(tmp_path_factory.mktemp("extreme"), content)


@pytest.mark.slow
@settings(SWEEP)
@given(content=extreme_numbers())
def test_a_far_out_value_is_refused_or_simulates_sweep(tmp_path_factory, content):
    _refused_or_walks(tmp_path_factory.mktemp("extreme"), content)


@settings(max_examples=15)
@given(case=surely_invalid())
def test_simulate_on_a_damaged_file_exits_2_without_a_traceback(tmp_path_factory, case):
    folder = tmp_path_factory.mktemp("cli")
    scenario, out = folder / "site.yaml", folder / "walk"
    scenario.write_bytes(case[0])
    stderr = io.StringIO()
    with contextlib.redirect_stderr(stderr):
        status = main(["simulate", str(scenario), *CLI_ARGS, "--out", str(out)])
    printed = stderr.getvalue()
    assert status == 2, printed
    assert "Traceback" not in printed
    assert printed.startswith("indoorsim: ") and str(scenario) in printed
    assert not out.exists()


def test_the_damaged_base_file_has_every_top_level_key():
    # Defaults written out: damage reaches every section of the schema, not just the
    # keys the minimal file spells.
    assert {p[0] for p in NODES} == set(Scenario.model_fields)
    assert len(NUMBERS) > 50
