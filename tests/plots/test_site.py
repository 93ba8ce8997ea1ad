"""Site figures: the plan drawing, the site map, and field maps that show the real fields."""

from __future__ import annotations

import matplotlib.pyplot as plt
import numpy as np
import pytest
from matplotlib.backends.backend_agg import FigureCanvasAgg
from matplotlib.figure import Figure

from indoorsim.plots.site import (
    draw_plan,
    plot_site_fields,
    plot_site_map,
    sample_site_fields,
    save_site_plots,
)
from indoorsim.world.site import Site

# Coarse enough to keep the suite fast, fine enough that every room has cells.
RESOLUTION = 0.25


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
