"""Figures: a site's plan, sources and fields; one walk's streams and track; leaderboard results.

Modules:

* :mod:`~indoorsim.plots.style` — colours by material, source and carrying
  mode, marker and figure sizes, free-standing figures, PNG file names.
* :mod:`~indoorsim.plots.site` — :func:`draw_plan`, :func:`plot_site_map`,
  :func:`sample_site_fields` / :func:`plot_site_fields` (B, lux and RSS heat
  maps at phone height), :func:`save_site_plots`.
* :mod:`~indoorsim.plots.recording` — :func:`plot_recording_streams`,
  :func:`plot_recording_track`, :func:`save_recording_plots` for a simulated
  walk or a real phone log.
* :mod:`~indoorsim.plots.results` — :func:`plot_error_cdfs`,
  :func:`plot_tracks`, :func:`plot_named_cdfs`, :func:`plot_training_curves`,
  :func:`plot_realism_profiles`, :func:`plot_robustness`, :func:`plot_sim_to_real`.

The public functions are re-exported here (``from indoorsim.plots import
draw_plan``). Every figure is a free-standing :class:`matplotlib.figure.Figure`
on an Agg canvas: nothing is registered with ``pyplot``, so plotting many
sites in one process (or in a worker) leaves no figures behind and never
needs a display. Importing this package imports matplotlib: modules that plot
only now and then import it inside the function that plots.
"""

from __future__ import annotations

from indoorsim.plots.recording import (
    plot_recording_streams,
    plot_recording_track,
    save_recording_plots,
)
from indoorsim.plots.results import (
    plot_error_cdfs,
    plot_named_cdfs,
    plot_realism_profiles,
    plot_robustness,
    plot_sim_to_real,
    plot_tracks,
    plot_training_curves,
)
from indoorsim.plots.site import (
    FieldGrid,
    draw_plan,
    plot_site_fields,
    plot_site_map,
    sample_site_fields,
    save_site_plots,
)
from indoorsim.plots.style import MATERIAL_COLOURS, MODE_COLOURS, SOURCE_COLOURS, save_figures

__all__ = [
    "MATERIAL_COLOURS",
    "MODE_COLOURS",
    "SOURCE_COLOURS",
    "FieldGrid",
    "draw_plan",
    "plot_error_cdfs",
    "plot_named_cdfs",
    "plot_realism_profiles",
    "plot_recording_streams",
    "plot_recording_track",
    "plot_robustness",
    "plot_sim_to_real",
    "plot_site_fields",
    "plot_site_map",
    "plot_tracks",
    "plot_training_curves",
    "sample_site_fields",
    "save_figures",
    "save_recording_plots",
    "save_site_plots",
]
