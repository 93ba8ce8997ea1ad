"""Figures: the plan drawing, the site map, field maps that show the real fields, and walks."""

from __future__ import annotations

import matplotlib.pyplot as plt
import numpy as np
import pandas as pd
import pytest
from matplotlib.backends.backend_agg import FigureCanvasAgg
from matplotlib.figure import Figure

import indoorsim
from indoorsim.io.recording import MissingStreamError, Recording
from indoorsim.plots import (
    MODE_COLOURS,
    draw_plan,
    plot_recording_streams,
    plot_recording_track,
    plot_site_fields,
    plot_site_map,
    sample_site_fields,
    save_recording_plots,
    save_site_plots,
)
from indoorsim.scenario import parse_scenario
from indoorsim.simulate import simulate
from indoorsim.world.site import Site
from tests.conftest import box_scenario

# Coarse enough to keep the suite fast, fine enough that every room has cells.
RESOLUTION = 0.25


@pytest.fixture(scope="module")
def site() -> Site:
    """A small office with every kind of element the plots draw."""
    walls = box_scenario()["walls"] + [
        {"from": [6, 0], "to": [6, 6], "thickness": 0.12, "material": "drywall"},
        {"from": [6, 3], "to": [10, 3], "thickness": 0.05, "material": "glass"},
    ]
    scenario = box_scenario(
        name="test-office",
        walls=walls,
        doors=[{"position": [6, 1.5]}, {"position": [8, 3]}],
        rooms=[{"name": "hall", "polygon": [[0, 0], [6, 0], [6, 6], [0, 6]]}],
        pillars=[{"center": [3, 3]}],
        obstacles=[
            {"kind": "desk", "center": [1.5, 5], "size": [1.4, 0.7]},
            {
                "kind": "cabinet",
                "center": [9, 5.5],
                "size": [1.0, 0.5],
                "height": 1.8,
                "steel_volume_m3": 0.01,
            },
        ],
        luminaires=[
            {"position": [2, 2, 3], "intensity_cd": 800},
            {"position": [8, 1.5, 3], "intensity_cd": 800},
        ],
        magnetic={
            "dipoles": [{"position": [4.5, 1, -0.3], "moment": [0, 0, 25]}],
            "rebar": [{"z": -0.15}],
        },
        wifi=[
            {"bssid": "02:00:00:00:00:01", "position": [1, 1, 2.5]},
            {"bssid": "02:00:00:00:00:2A", "position": [9, 1, 2.5]},
        ],
        routes={
            "tour": {"waypoints": [[1, 1.5], [5, 1.5], [8, 1.5]]},
            "errand": {"start": [1, 4], "goal": [8, 4.5]},
        },
    )
    return Site(parse_scenario(scenario))


@pytest.fixture(scope="module")
def field_figures(site: Site) -> dict[str, Figure]:
    return plot_site_fields(site, resolution=RESOLUTION)


def _cells(fig: Figure) -> tuple[np.ma.MaskedArray, np.ndarray]:
    """The heat map's values as drawn, and the (ny, nx, 3) centres of its cells at 1.2 m."""
    image = fig.axes[0].images[0]
    values = image.get_array()
    left, right, bottom, top = image.get_extent()
    ny, nx = values.shape
    x = left + (np.arange(nx) + 0.5) * (right - left) / nx
    y = bottom + (np.arange(ny) + 0.5) * (top - bottom) / ny
    gx, gy = np.meshgrid(x, y)
    return values, np.stack([gx, gy, np.full_like(gx, 1.2)], axis=-1)


def test_every_field_map_is_masked_exactly_outside_the_walkable_area(site, field_figures):
    assert set(field_figures) == {"Bx", "By", "Bz", "B", "lux", "rss_02:00:00:00:00:01"}
    for key, fig in field_figures.items():
        values, centres = _cells(fig)
        walkable = site.plan.is_walkable(centres.reshape(-1, 3)).reshape(values.shape)
        np.testing.assert_array_equal(np.ma.getmaskarray(values), ~walkable, err_msg=key)
        assert np.isfinite(values.compressed()).all(), key
    # Inside the building too: pillars, desks and walls are holes in the map.
    grid = sample_site_fields(site, resolution=RESOLUTION)
    ix, iy = np.argmin(np.abs(grid.x - 3.0)), np.argmin(np.abs(grid.y - 3.0))
    assert not grid.walkable[iy, ix]
    assert np.isnan(grid.magnetic_uT[iy, ix]).all()
    assert np.isnan(grid.illuminance_lux[iy, ix])


def _expected(site: Site, key: str, points: np.ndarray) -> np.ndarray:
    if key in ("Bx", "By", "Bz"):
        return site.magnetic_field(points)[:, "xyz".index(key[1])]
    if key == "B":
        return np.linalg.norm(site.magnetic_field(points), axis=1)
    if key == "lux":
        return site.illuminance(points, np.tile([0.0, 0.0, 1.0], (len(points), 1)))
    return site.rss(points)[:, site.radio.bssids.index(key.removeprefix("rss_"))]


@pytest.mark.parametrize("key", ["Bx", "By", "Bz", "B", "lux", "rss_02:00:00:00:00:01"])
def test_maps_show_the_sites_own_field_at_their_cells(site, field_figures, key):
    values, centres = _cells(field_figures[key])
    rows, cols = np.nonzero(~np.ma.getmaskarray(values))
    pick = np.random.default_rng(0).choice(len(rows), size=6, replace=False)
    points = centres[rows[pick], cols[pick]]
    np.testing.assert_allclose(
        values[rows[pick], cols[pick]], _expected(site, key, points), rtol=1e-9, atol=1e-9
    )


def test_field_maps_vary_where_the_sources_are(site, field_figures):
    """The |B| map peaks next to steel, the light map under a luminaire."""
    values, centres = _cells(field_figures["B"])
    deviation = np.abs(values - np.linalg.norm(site.magnetic.earth_field_uT))
    row, col = np.unravel_index(np.ma.argmax(deviation), values.shape)
    steel = site.magnetic.positions[site.magnetic.sources != "rebar", :2]
    assert np.min(np.linalg.norm(steel - centres[row, col, :2], axis=1)) < 1.0
    values, centres = _cells(field_figures["lux"])
    row, col = np.unravel_index(np.ma.argmax(values), values.shape)
    lights = np.array([lum.position[:2] for lum in site.scenario.luminaires])
    assert np.min(np.linalg.norm(lights - centres[row, col, :2], axis=1)) < 0.5


def test_rss_map_of_a_chosen_ap_and_an_unknown_one(site):
    figures = plot_site_fields(site, resolution=1.0, ap="02:00:00:00:00:2a")
    assert "rss_02:00:00:00:00:2A" in figures
    with pytest.raises(ValueError, match="02:00:00:00:00:01"):
        plot_site_fields(site, resolution=1.0, ap="aa:bb:cc:dd:ee:ff")


@pytest.mark.parametrize(
    ("height", "resolution"), [(1.2, 0.0), (1.2, 25.0), (0.0, 0.5), (3.0, 0.5)]
)
def test_sampling_rejects_a_bad_grid(site, height, resolution):
    with pytest.raises(ValueError, match=r"height|resolution"):
        sample_site_fields(site, height=height, resolution=resolution)


def test_plan_drawing_leaves_doors_open_and_rooms_empty(site):
    fig = Figure(dpi=100)
    FigureCanvasAgg(fig)
    ax = fig.add_subplot()
    handles = {h.get_label(): h for h in draw_plan(ax, site.plan, legend=False)}
    fig.canvas.draw()
    pixels = np.asarray(fig.canvas.buffer_rgba())[..., :3] / 255

    def colour_at(x: float, y: float) -> np.ndarray:
        px, py = ax.transData.transform((x, y))
        return pixels[pixels.shape[0] - 1 - int(py), int(px)]

    def fill(label: str) -> np.ndarray:
        return np.asarray(handles[label].get_facecolor()[:3])

    np.testing.assert_allclose(colour_at(6.0, 4.5), fill("wall: drywall"), atol=0.02)
    np.testing.assert_allclose(colour_at(6.0, 1.5), fill("walkable floor"), atol=0.02)  # door
    np.testing.assert_allclose(colour_at(0.0, 3.0), fill("wall: concrete"), atol=0.02)
    # The outer walls' union is a ring: the room inside it stays floor.
    np.testing.assert_allclose(colour_at(4.5, 4.0), fill("walkable floor"), atol=0.02)
    assert ax.get_aspect() == 1.0
    assert ax.get_xlabel() == "x (m)"


def test_site_map_labels_every_kind_of_source(site):
    fig = plot_site_map(site)
    labels = {t.get_text() for t in fig.legends[0].get_texts()}
    assert {
        "wall: concrete",
        "wall: drywall",
        "wall: glass",
        "pillar: concrete",
        "desk",
        "furniture",
        "luminaire",
        "magnetic: dipole",
        "magnetic: pillar",
        "magnetic: obstacle",
        "magnetic: rebar",
    } <= labels
    texts = {t.get_text() for t in fig.axes[0].texts}
    assert {"00:01", "00:2a", "tour", "errand", "hall"} <= texts
    # The start/goal route is drawn as the planned path, which bends through the doors.
    errand = next(line for line in fig.axes[0].lines if line.get_label() == "route errand")
    assert len(errand.get_xdata()) > 2
    assert site.plan.is_walkable(np.column_stack(errand.get_data())).all()


def test_saving_writes_pngs_and_leaves_no_pyplot_figures(site, tmp_path):
    before = plt.get_fignums()
    paths = save_site_plots(site, tmp_path / "new", resolution=1.0, dpi=40)
    assert plt.get_fignums() == before
    assert [p.name for p in paths] == [
        f"test-office_{key}.png"
        for key in ("map", "Bx", "By", "Bz", "B", "lux", "rss_02-00-00-00-00-01")
    ]
    assert all(p.read_bytes().startswith(b"\x89PNG\r\n\x1a\n") for p in paths)


# ------------------------------------------------------------------- recordings

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
