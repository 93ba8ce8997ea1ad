"""Sim-to-real: real traces scored beside their simulated twins."""

from __future__ import annotations

from dataclasses import dataclass
from typing import ClassVar

import numpy as np
import pandas as pd
import pytest

from indoorsim.benchmark.evaluation import evaluate_recording
from indoorsim.benchmark.sim_to_real import (
    SIGNALS,
    SPEED_READ_KEYS,
    TwinResults,
    _approach,
    _leg_parts,
    _pace,
    _path_ratio,
    _speed_reads,
    as_real_log,
    passing_times,
    shared_turns,
    twin_summary,
    walk_signals,
    waypoint_lead,
    write_sim_to_real,
    write_twin_section,
)
from indoorsim.io.recording import Recording
from indoorsim.scenario.load import load_site
from indoorsim.simulate import simulate


def test_without_real_walks_the_report_says_so(tmp_path):
    seconds = write_sim_to_real(tmp_path, tmp_path / "nothing-here")
    text = (tmp_path / "sim_to_real.md").read_text()
    assert "No Oxford step-counter walks" in text and "No competition floor" in text
    assert seconds >= 0


def test_passing_times_find_each_waypoint_in_order_even_on_a_walk_back():
    # Out along x and back: the first waypoint is passed twice; the first pass counts.
    x = np.r_[np.linspace(0, 10, 101), np.linspace(10, 0, 101)[1:]]
    truth = pd.DataFrame({"body_x": x, "body_y": np.zeros_like(x)})
    at = passing_times(truth, np.array([[2.0, 0.0], [10.0, 0.0], [2.0, 0.0]]))
    np.testing.assert_array_equal(at, [20, 100, 180])


def test_a_twin_is_scored_as_a_real_log_at_its_waypoints():
    rec = simulate(load_site("minimal_room"), route="main", device="nexus_5x", seed=0)
    route = load_site("minimal_room").scenario.routes["main"]
    twin = as_real_log(rec, np.asarray(route.waypoints, dtype=float))
    assert "truth" not in twin.streams and "steps" not in twin.streams
    marks = twin.waypoints[["x", "y"]].to_numpy()
    # Marked as a surveyor marks them: at the waypoints' positions.
    np.testing.assert_array_equal(marks, np.asarray(route.waypoints, dtype=float))
    passing = twin.waypoints.index.to_numpy()
    assert np.all(np.diff(passing) > 0)
    # The body passes within reach of each waypoint when it is marked.
    truth = rec.truth
    at = np.searchsorted(truth.index.to_numpy(), passing)
    body = truth[["body_x", "body_y"]].to_numpy()[at]
    assert np.linalg.norm(body - marks, axis=1).max() < 1.0
    # Marked 0.8 s early, each mark moves 0.8 s back (the first no earlier than the start).
    early = as_real_log(rec, np.asarray(route.waypoints, dtype=float), lead_s=0.8)
    np.testing.assert_allclose(early.waypoints.index.to_numpy()[1:], passing[1:] - 0.8, atol=1e-12)
    assert early.waypoints.index[0] == max(passing[0] - 0.8, truth.index[0])
    # Marked before the walk began, every mark is held at its start, still in order.
    clamped = as_real_log(rec, np.asarray(route.waypoints, dtype=float), lead_s=1e3)
    times = clamped.waypoints.index.to_numpy()
    assert times[0] == truth.index[0] and np.all(np.diff(times) > 0)


@dataclass(kw_only=True)
class _Truth:
    """A perfect estimator: answers where the walker truly is at each window's end."""

    truth: pd.DataFrame
    name: ClassVar[str] = "truth"
    needs: ClassVar[tuple[str, ...]] = ()
    uses: ClassVar[tuple[str, ...]] = ()

    def fit(self, site, train) -> None:
        """Nothing to learn."""

    def reset(self, start) -> None:
        """Nothing to forget."""

    def act(self, obs) -> np.ndarray:
        t = self.truth.index.to_numpy(dtype=float)
        end = float(np.nanmax(obs["t"]))
        return np.array([np.interp(end, t, self.truth[k].to_numpy()) for k in ("x", "y")])


@pytest.mark.parametrize("lead_s", [0.0, 1.0])
def test_a_perfect_estimator_walks_the_scored_waypoints_distance(lead_s):
    """The walked-distance ratio of the truth itself on a corridor walk of two long legs,
    scored as a real log whose marks come ``lead_s`` before the walker passes its
    waypoints: 1 within 1 %. Read from mark to mark instead, the marked 1 s early read
    1.023 (a lead's walk short of the first waypoint, nearer the last)."""
    site = load_site("han2023_corridor")
    rec = simulate(site, route="trajectory", mode="handheld", device="nexus_5x", seed=0)
    marks = np.asarray(site.scenario.routes["trajectory"].waypoints, dtype=float)
    twin = as_real_log(rec, marks, lead_s=lead_s)
    result = evaluate_recording(f"{__name__}:_Truth", twin, params={"truth": rec.truth})
    assert _path_ratio(result, lead_s) == pytest.approx(1.0, abs=0.01)
    # Over the scored marks' polyline, from every answer (one a second).
    scored = result.estimates[["true_x", "true_y"]].to_numpy()
    polyline = np.linalg.norm(np.diff(scored, axis=0), axis=1).sum()
    assert result.metrics["path_m"] == pytest.approx(polyline)
    assert np.all(np.diff(result.track["t"]) == pytest.approx(1.0, abs=0.05))


def test_leg_parts_split_a_track_near_the_marks_from_between_them():
    """Three legs of 10 m walked in 10 s each, marks 1 s before the walker passes their
    waypoints; a track answering every second at 1 m/s reads as paced. The first leg is
    left out; of the other two, 2 s at each end of each are near the marks (0.2 of 10 s):
    8 m near, 12 m between. A track that stands for each leg's first 2 s and walks its
    10 m in the other 8 s reads 2.5 m near the marks on each leg (2 s standing, the
    last 2 s at 1.25 m/s) and 7.5 m between: under 1 near, over 1 between, though it
    walks every leg's length in its time."""
    marks = np.array([[0.0, 0.0], [10.0, 0.0], [10.0, 10.0], [0.0, 10.0]])
    times = np.array([0.0, 10.0, 20.0, 30.0]) - 1.0
    waypoints = pd.DataFrame(marks, columns=["x", "y"], index=pd.Index(times, name="t"))
    rec = Recording(streams={"waypoints": waypoints})
    t = np.arange(0.0, 31.0)
    along = np.interp(t, [0, 10, 20, 30], [0, 10, 20, 30])
    xy = np.column_stack(
        [
            np.interp(along, [0, 10, 20, 30], marks[:, 0]),
            np.interp(along, [0, 10, 20, 30], marks[:, 1]),
        ]
    )

    @dataclass
    class _Result:
        track: pd.DataFrame

    result = _Result(track=pd.DataFrame({"t": t, "x": xy[:, 0], "y": xy[:, 1]}))
    parts = _leg_parts(result, rec, lead_s=1.0)
    assert parts["paced_near_m"] == pytest.approx(8.0)
    assert parts["paced_between_m"] == pytest.approx(12.0)
    assert parts["read_near_m"] == pytest.approx(8.0)
    assert parts["read_between_m"] == pytest.approx(12.0)
    # Standing 2 s at each waypoint, then the leg's 10 m in its other 8 s.
    hold = np.concatenate([[0.0, 0.0], np.linspace(0.0, 10.0, 9)[1:]])
    along = np.concatenate([[0.0], hold, 10.0 + hold, 20.0 + hold])[: len(t)]
    xy = np.column_stack(
        [
            np.interp(along, [0, 10, 20, 30], marks[:, 0]),
            np.interp(along, [0, 10, 20, 30], marks[:, 1]),
        ]
    )
    result = _Result(track=pd.DataFrame({"t": t, "x": xy[:, 0], "y": xy[:, 1]}))
    parts = _leg_parts(result, rec, lead_s=1.0)
    assert parts["read_near_m"] == pytest.approx(2 * 2.5)  # 0 + 2·1.25 on each leg
    assert parts["read_between_m"] == pytest.approx(2 * 7.5)  # 6 s at 1.25 m/s


def test_the_approach_to_each_waypoint_is_read_from_the_steps():
    """Two legs of 10 s, passed 1 s after their marks: steps of swing 8 every 0.5 s
    mid-leg, of swing 4 every 1 s over each leg's last 2 s; the first 2 s of each leg
    count to neither."""

    @dataclass
    class _Step:
        t: float
        a_max: float
        a_min: float = 0.0

    waypoints = pd.DataFrame(
        {"x": [0.0, 10.0, 10.0], "y": [0.0, 0.0, 10.0]},
        index=pd.Index([-1.0, 9.0, 19.0], name="t"),
    )
    rec = Recording._from_built({"waypoints": waypoints}, {})
    steps = []
    for start in (0.0, 10.0):
        steps += [_Step(start + t, 6.0) for t in (0.25, 1.25)]  # leaving: neither part
        steps += [_Step(start + 2.0 + 0.5 * k, 8.0) for k in range(12)]  # 2 … 7.5 s
        steps += [_Step(start + t, 4.0) for t in (8.5, 9.5)]
    out = _approach(rec, steps, lead_s=1.0)
    assert out == pytest.approx(
        {
            "approach_step_hz": 1.0,
            "approach_swing": 4.0,
            "between_step_hz": 2.0,
            "between_swing": 8.0,
        }
    )
    # Without waypoints there is nothing to approach.
    assert np.isnan(_approach(Recording._from_built({}, {}), steps, 1.0)["approach_step_hz"])


def test_speed_reads_bin_each_answer_interval_by_the_true_speed():
    """A phone walking 0.5 m/s for 4 s, then 1.4 m/s for 4 s, then 2 m/s for 2 s, and a
    track answering every second that reads the slow part right, the brisk part at half
    and the fast part at 1.1."""
    tt = np.arange(0.0, 10.001, 0.01)
    speed = np.where(tt < 4.0, 0.5, np.where(tt < 8.0, 1.4, 2.0))
    x = np.concatenate([[0.0], np.cumsum(speed[:-1] * 0.01)])
    truth = pd.DataFrame({"x": x, "y": 0.0 * x}, index=pd.Index(tt, name="t"))
    t = np.arange(0.0, 11.0)
    true_x = np.interp(t, tt, x)
    steps = np.diff(true_x) * np.where(t[1:] <= 4.0, 1.0, np.where(t[1:] <= 8.0, 0.5, 1.1))

    @dataclass
    class _Result:
        track: pd.DataFrame

    track = pd.DataFrame({"t": t, "x": np.concatenate([[0.0], np.cumsum(steps)]), "y": 0.0 * t})
    out = _speed_reads(_Result(track=track), truth)
    assert out["true_speed0_m"] == pytest.approx(2.0)
    assert out["read_speed0_m"] == pytest.approx(2.0)
    assert out["true_speed2_m"] == pytest.approx(5.6)  # 1.4 m/s: the 1.3–1.5 bin
    assert out["read_speed2_m"] == pytest.approx(2.8)
    assert out["true_speed3_m"] == pytest.approx(4.0)
    assert out["read_speed3_m"] == pytest.approx(4.4)
    assert out["true_speed1_m"] == 0.0
    # A real trace has no truth to bin by.
    assert np.isnan(_speed_reads(_Result(track=track), None)["read_speed0_m"])


@pytest.mark.parametrize("sway", [0.0, 0.3])
def test_the_lead_of_a_corner_mark_is_read_from_the_gyros_turn(sway):
    """A 90° left turn centred 0.8 s after the corner was marked, on a level phone,
    with and without the stride's sway of the heading (0.3 rad/s at 0.9 Hz), which
    a window held on the mark would let pull the centre toward it."""
    t = np.arange(0.0, 20.0, 0.02)
    centre, width = 10.8, 0.4
    rate = np.exp(-0.5 * ((t - centre) / width) ** 2)
    rate *= (np.pi / 2) / np.trapezoid(rate, t)
    rate += sway * np.sin(2 * np.pi * 0.9 * t)
    index = pd.Index(t, name="t")
    streams = {
        "gyro": pd.DataFrame({"x": 0 * t, "y": 0 * t, "z": rate}, index=index),
        "accel": pd.DataFrame({"x": 0 * t, "y": 0 * t, "z": 9.81 + 0 * t}, index=index),
        "waypoints": pd.DataFrame(
            {"x": [0.0, 10.0, 10.0], "y": [0.0, 0.0, 10.0]},
            index=pd.Index([0.0, 10.0, 19.0], name="t"),
        ),
    }
    lead = waypoint_lead(Recording._from_built(streams, {}))
    np.testing.assert_allclose(lead, [0.8], atol=0.01 if sway == 0 else 0.05)
    # A right turn where the map turns left is no turn of that corner's.
    streams["gyro"]["z"] = -rate
    assert len(waypoint_lead(Recording._from_built(streams, {}))) == 0


def test_pace_is_the_short_and_the_long_legs_length_over_their_time():
    waypoints = pd.DataFrame(
        {"x": [0.0, 2.0, 2.0, 12.0, 12.0], "y": [0.0, 0.0, 3.0, 3.0, 8.0]},
        index=pd.Index([0.0, 4.0, 7.0, 15.0, 20.0], name="t"),
    )
    pace = _pace(Recording._from_built({"waypoints": waypoints}, {}))
    # 2 m in 4 s and 3 m in 3 s; 10 m in 8 s; the 5 m leg is neither.
    assert pace == pytest.approx({"pace_short": 5.0 / 7.0, "pace_long": 10.0 / 8.0})
    assert np.isnan(
        _pace(Recording._from_built({"waypoints": waypoints.iloc[:2]}, {}))["pace_long"]
    )


def test_a_twin_shows_every_signal_the_table_compares():
    site = load_site("han2023_corridor")
    route = next(iter(site.scenario.routes))
    rec = simulate(site, route=route, mode=[(0.0, "handheld", {"pitch_deg": 0.0})], seed=0)
    twin = as_real_log(rec, np.asarray(site.scenario.routes[route].waypoints, dtype=float))
    signals = walk_signals(twin)
    assert set(signals) == set(SIGNALS)
    # The hard iron only where the walk turns far enough to show it; this one does not.
    assert np.isnan(signals.pop("hard_iron"))
    # Its legs are all long: the corridor's 20 m runs at the route's 1.1 m/s or so.
    assert np.isnan(signals.pop("pace_short"))
    assert signals["pace_long"] == pytest.approx(1.1, rel=0.15)
    assert signals["mag_std_iron_free"] == signals["mag_std"]
    assert all(np.isfinite(v) for v in signals.values()), signals
    # A held phone bobs more than it surges, and the field varies along a real corridor.
    assert signals["bob_step"] > 3 * signals["surge_step"]
    assert signals["mag_std"] > signals["mag_std_long"] > 0


def _scores() -> pd.DataFrame:
    rows = []
    for est, real, sim in (("a", 2.0, 1.0), ("b", 3.0, 3.0), ("c", 4.0, 5.0)):
        for trace in ("t1", "t2"):
            rows.append(
                {
                    "trace": trace,
                    "estimator": est,
                    "data": "real",
                    "seed": -1,
                    "ae": real,
                    "rmse": real,
                    "path_ratio": 1.0,
                    "ae_aligned": real / 2,
                    # Turned one way on one trace, the other way on the other.
                    "turn_deg": 10.0 if trace == "t1" else -20.0,
                    # Read short near the marks, as paced between them.
                    "read_near_m": 3.0,
                    "paced_near_m": 4.0,
                    "read_between_m": 8.0,
                    "paced_between_m": 8.0,
                }
            )
            for seed, jitter in ((0, -0.5), (1, 0.5)):
                rows.append(
                    {
                        "trace": trace,
                        "estimator": est,
                        "data": "sim",
                        "seed": seed,
                        "ae": sim + jitter,
                        "rmse": sim,
                        "path_ratio": 0.9,
                        "ae_aligned": sim / 2 + jitter,
                        "turn_deg": 4.0 * jitter,
                        "read_near_m": 4.0 + jitter,
                        "paced_near_m": 4.0,
                        "read_between_m": 8.0,
                        "paced_between_m": 10.0,
                        # Read short at the brisk pace only: 9 of 10 m there, 30 of 30 usual.
                        **dict.fromkeys(SPEED_READ_KEYS, 0.0),
                        "read_speed1_m": 30.0,
                        "true_speed1_m": 30.0,
                        "read_speed2_m": 9.0,
                        "true_speed2_m": 10.0,
                    }
                )
    return pd.DataFrame(rows)


def test_shared_turns_correlate_each_estimators_turn_with_the_references():
    """On the real traces one estimator turns as the reference does (2·turn + 1: r = 1),
    on the twins against it (r = −1, each trace's two seeds averaged first); one that
    never turns has no correlation."""
    reference = {"t1": 5.0, "t2": -10.0, "t3": 15.0, "t4": 0.0}
    rows = []
    for trace, turn in reference.items():
        rows += [
            {"trace": trace, "data": "real", "estimator": "pdr-basic", "turn_deg": turn},
            {"trace": trace, "data": "real", "estimator": "x", "turn_deg": 2 * turn + 1},
            {"trace": trace, "data": "real", "estimator": "still", "turn_deg": 0.0},
        ]
        for jitter in (-3.0, 3.0):  # two seeds a trace
            rows += [
                {"trace": trace, "data": "sim", "estimator": "pdr-basic", "turn_deg": turn},
                {"trace": trace, "data": "sim", "estimator": "x", "turn_deg": -turn + jitter},
                {"trace": trace, "data": "sim", "estimator": "still", "turn_deg": 0.0},
            ]
    shared = shared_turns(pd.DataFrame(rows)).set_index("estimator")
    assert list(shared.index) == ["x", "still"]
    assert shared.loc["x", "real"] == pytest.approx(1.0)
    assert shared.loc["x", "sim"] == pytest.approx(-1.0)
    assert shared.loc["still"].isna().all()


def test_the_summary_gives_each_estimators_real_to_sim_ratio_and_the_rank_agreement():
    summary, tau = twin_summary(_scores())
    assert list(summary["ratio"].round(6)) == [2.0, 1.0, 0.8]
    assert tau == pytest.approx(1.0)  # the same order on both
    assert (summary["path_ratio_sim"] == 0.9).all()
    # Once each track is turned about its start: the shapes' errors and the turns' sizes.
    assert list(summary["aligned_ratio"].round(6)) == [2.0, 1.0, 0.8]
    assert (summary["turn_real"] == 15.0).all()  # median of |10| and |−20|
    assert (summary["turn_sim"] == 2.0).all()  # |∓2| averaged over seeds first


def test_the_section_names_the_signals_on_which_the_twins_depart(tmp_path):
    signals = []
    for trace in ("t1", "t2"):
        real = dict.fromkeys(SIGNALS, 1.0) | {"acc_std": 3.0, "yaw_stride": 0.5}
        # A hard iron shown by one real trace only: its twin's alone is compared.
        real["hard_iron"] = 10.0 if trace == "t2" else np.nan
        signals.append({"trace": trace, "data": "real", "seed": -1} | real)
        for seed in (0, 1):
            sim = dict.fromkeys(SIGNALS, 1.0) | {"hard_iron": 3.0 if trace == "t1" else 10.0}
            signals.append({"trace": trace, "data": "sim", "seed": seed} | sim)
    results = TwinResults(scores=_scores(), signals=pd.DataFrame(signals), left_out={})
    text = "\n".join(write_twin_section(tmp_path, results))
    assert "| a | 2.00 | 1.00 | 2.00 (outside 0.8–1.25) |" in text
    assert "| a | 15.0 | 2.0 | 1.00 | 0.50 | 2.00 (outside 0.8–1.25) |" in text
    # Near the marks and between them, over the legs' mean speeds: sums over the traces.
    assert "| a | 0.75 | 1.00 | 1.00 | 0.80 |" in text
    # The twins' speed read by true speed, with the share of the distance walked at it.
    assert "| a | nan (0.00) | 1.00 (0.75) | 0.90 (0.25) | nan (0.00) |" in text
    departs = next(line for line in text.splitlines() if line.startswith("Where the twins depart"))
    assert "‖a‖ std while walking (3.00)" in departs
    assert "rate of turn at the stride rate (0.50)" in departs
    assert "step rate" not in departs
    assert "residual hard iron" not in departs  # 10 against 10 on t2; t1's 3 is unpaired
    # Each signal row says over how many traces its medians are.
    assert "| ‖a‖ std while walking (m/s²) | 2 | 3 | 1 | 3.00 |" in text
    iron = next(line for line in text.splitlines() if "residual hard iron" in line)
    assert iron.startswith(
        "| the magnetometer's residual hard iron, where the turns show it (µT) | 1 |"
    )
