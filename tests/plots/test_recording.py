"""Recording figures: a walk's sensor streams and its true track, simulated or a real log."""

from __future__ import annotations

import matplotlib.pyplot as plt
import numpy as np
import pandas as pd
import pytest
from matplotlib.figure import Figure

import indoorsim
from indoorsim.io.recording import MissingStreamError, Recording
from indoorsim.plots.recording import (
    plot_recording_streams,
    plot_recording_track,
    save_recording_plots,
)
from indoorsim.plots.style import MODE_COLOURS
from indoorsim.simulate import simulate
from indoorsim.world.site import Site

STREAM_LABELS = [
    "accel (m/s²)",
    "gyro (rad/s)",
    "mag (µT)",
    "light (lux)",
    "WiFi RSS (dBm)",
    "APs per scan",
]


@pytest.fixture(scope="module")
def walk(site: Site) -> Recording:
    """A walk along the office's ``tour``, from hand to ear to pocket."""
    schedule = [(0.0, "handheld"), (2.0, "calling"), (4.0, "pocketed")]
    return simulate(site, route="tour", mode=schedule, device="honor_50", seed=0)


def _frame(t, **columns) -> pd.DataFrame:
    return pd.DataFrame(columns, index=pd.Index(np.asarray(t, dtype=float), name="t"))


def _real_log(**streams: pd.DataFrame) -> Recording:
    """A recording shaped like a real phone log: a little IMU data and the given streams."""
    t = np.arange(0.0, 20.0, 0.5)
    accel = _frame(t, x=np.zeros_like(t), y=np.zeros_like(t), z=np.full_like(t, 9.8))
    return Recording(streams={"accel": accel, **streams}, meta={"device": "phone"})


def _panel(fig: Figure, label: str):
    return next(ax for ax in fig.axes if ax.get_ylabel() == label)


def test_stream_panels_are_those_of_the_streams_present(walk):
    assert [ax.get_ylabel() for ax in plot_recording_streams(walk).axes] == STREAM_LABELS
    real = Recording(streams={k: walk.streams[k] for k in ("accel", "gyro", "mag", "wifi")})
    fig = plot_recording_streams(real)
    assert [ax.get_ylabel() for ax in fig.axes] == [STREAM_LABELS[i] for i in (0, 1, 2, 4, 5)]
    assert not fig.axes[0].collections  # no step lines
    with pytest.raises(ValueError, match="nothing to plot"):
        plot_recording_streams(Recording(streams={"steps": walk.steps}))


def test_vector_panels_draw_the_samples_their_norm_and_the_true_steps(walk):
    ax = plot_recording_streams(walk).axes[0]
    lines = {line.get_label(): line for line in ax.lines}
    accel = walk.accel
    for axis in "xyz":
        np.testing.assert_array_equal(lines[axis].get_ydata(), accel[axis].to_numpy())
    np.testing.assert_allclose(lines["|a|"].get_ydata(), np.linalg.norm(accel.to_numpy(), axis=1))
    (steps,) = [c for c in ax.collections if c.get_label().startswith("true steps")]
    x = [segment[0, 0] for segment in steps.get_segments()]
    np.testing.assert_array_equal(x, walk.steps.index.to_numpy())


def test_each_mode_is_shaded_where_the_truth_is_in_it(walk):
    fig = plot_recording_streams(walk)
    t = walk.truth.index.to_numpy()
    modes = walk.truth["mode"].to_numpy()
    for ax in fig.axes:
        shaded = [p for p in ax.patches if p.get_alpha() == pytest.approx(0.08)]
        starts = sorted(p.get_x() for p in shaded)
        assert starts == [t[0], t[np.argmax(modes == "calling")], t[np.argmax(modes == "pocketed")]]
    legend = {text.get_text() for text in fig.legends[0].get_texts()}
    assert legend == {"handheld", "calling", "pocketed"}
    steady = Recording(streams={"accel": walk.accel, "truth": walk.truth.assign(mode="handheld")})
    assert not plot_recording_streams(steady).legends


@pytest.mark.parametrize(
    ("lux", "scale"), [([500.0, 120.0, 3.0, 0.5, 0.0], "symlog"), ([40.0, 55.0, 60.0], "linear")]
)
def test_light_goes_on_a_log_axis_when_it_spans_decades(lux, scale):
    rec = _real_log(light=_frame(np.arange(len(lux)), lux=lux))
    ax = _panel(plot_recording_streams(rec), "light (lux)")
    assert ax.get_yscale() == scale
    # Each reading holds until the next; the last one until the recording ends.
    (line,) = ax.lines
    assert line.get_drawstyle() == "steps-post"
    assert line.get_xdata()[-1] == rec.duration


def test_wifi_panels_show_the_strongest_aps_and_every_scans_count():
    # Eight APs over three scans: ap6 strongest, ap0 weakest; ap7 is loud but
    # heard once, its misses counting as ap0's RSS, so its mean ranks it sixth.
    rows = [(t, f"ap{k}", -40.0 - 5 * (6 - k)) for t in (1.0, 5.0, 9.0) for k in range(7)]
    rows.append((5.0, "ap7", -45.0))
    t, bssid, rss = zip(*sorted(rows), strict=True)
    rec = _real_log(wifi=_frame(t, bssid=list(bssid), rss=list(rss)))
    fig = plot_recording_streams(rec)
    assert [line.get_label() for line in _panel(fig, "WiFi RSS (dBm)").lines] == [
        "ap6",
        "ap5",
        "ap4",
        "ap3",
        "ap2",
    ]
    heights = [bar.get_height() for bar in _panel(fig, "APs per scan").patches]
    assert heights == [7, 8, 7]


def test_track_follows_the_truth_coloured_by_mode_on_the_plan(site, walk):
    fig = plot_recording_track(walk, site)
    ax = fig.axes[0]
    by_mode = {line.get_label(): line for line in ax.lines if line.get_label() in MODE_COLOURS}
    assert list(by_mode) == ["handheld", "calling", "pocketed"]
    for mode, line in by_mode.items():
        assert line.get_color() == MODE_COLOURS[mode]
    truth = walk.truth
    drawn = np.concatenate([line.get_xdata() for line in by_mode.values()])
    # Each stretch repeats the next one's first point, so the track has no gaps.
    assert len(drawn) == len(truth) + 2
    np.testing.assert_array_equal(np.unique(drawn), np.unique(truth["x"]))
    texts = [text.get_text() for text in ax.texts]
    assert [t.split(" at ")[0] for t in texts] == ["calling", "pocketed"]
    legend = {text.get_text() for text in fig.legends[0].get_texts()}
    assert {"wall: concrete", "planned route", f"true steps ({len(walk.steps)})"} <= legend
    assert ax.get_aspect() == 1.0


def test_track_finds_a_bundled_building_by_the_scenario_name_in_the_manifest():
    room = indoorsim.load_site("minimal_room")
    rec = simulate(room, route="main", device="ideal", seed=0)

    def legend(rec: Recording) -> set[str]:
        return {text.get_text() for text in plot_recording_track(rec).legends[0].get_texts()}

    assert "wall: drywall" in legend(rec)
    elsewhere = Recording(streams=rec.streams, meta={**rec.meta, "scenario": "elsewhere"})
    assert not any(label.startswith("wall") for label in legend(elsewhere))


def test_real_log_track_joins_its_waypoints_and_labels_revisits():
    xy = [[80.0, 90.0], [75.0, 95.0], [75.0, 91.0], [80.05, 90.0], [76.0, 92.0]]
    waypoints = _frame([0.0, 5.0, 10.0, 15.0, 19.5], x=[p[0] for p in xy], y=[p[1] for p in xy])
    fig = plot_recording_track(_real_log(waypoints=waypoints))
    ax = fig.axes[0]
    (path,) = [line for line in ax.lines if line.get_label().startswith("waypoints")]
    np.testing.assert_array_equal(np.column_stack(path.get_data()), xy)
    assert {t.get_text() for t in ax.texts} == {"0.0, 15.0 s", "5.0 s", "10.0 s", "19.5 s"}
    assert ax.get_aspect() == 1.0


def test_saving_a_recording_without_positions_writes_only_its_streams(tmp_path):
    before = plt.get_fignums()
    rec = _real_log()
    with pytest.raises(MissingStreamError, match="truth"):
        plot_recording_track(rec)
    paths = save_recording_plots(rec, tmp_path / "new", "log", dpi=40)
    assert [p.name for p in paths] == ["log_streams.png"]
    assert paths[0].read_bytes().startswith(b"\x89PNG\r\n\x1a\n")
    assert plt.get_fignums() == before
