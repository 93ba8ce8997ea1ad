"""The leaderboards as a static web site: ``leaderboards/site/``.

:func:`write_site` reads the CSVs that :func:`~indoorsim.benchmark.leaderboard.run_leaderboard`
wrote and writes ``site/index.html`` and one page per board present: each
scenario, the Han2023 and Chen2022 paper tables, realism and real data. The
pages are self-contained (inline CSS and script, no network): tables sort on a
click of a column header and filter by text, by estimator, mode or other
categorical columns, and a metric selector shows the headline (AE, RMSE,
CEP95 on the scenario boards), every metric, or one (sorted by it). Every
row carries its provenance (git revision, package version, devices, window) in
its tooltip and in a last column. Plots are the board's own PNGs, linked as
``../NAME.png``.

Rebuild it alone from an existing folder: ``indoorsim leaderboard --site-only``.
"""

from __future__ import annotations

import html
import json
import math
from collections.abc import Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import pandas as pd

__all__ = ["Page", "Table", "write_site"]

SCENARIO_KEYS = ("estimator", "mode", "seeds")
SCENARIO_METRICS = (
    "ae",
    "rmse",
    "me",
    "min",
    "sd",
    "cep50",
    "cep75",
    "cep95",
    "final_error",
    "error_per_100m",
    "heading_mae_deg",
    "step_count_error_pct",
    "wall_crossings",
    "latency_ms_mean",
)
PROVENANCE = (
    "git_revision",
    "package_version",
    "env_id",
    "route",
    "device",
    "survey_device",
    "window_s",
    "n_train",
    "train_routes",
    "params",
    "source",
)
HEADLINE = ("ae", "rmse", "cep95")
# Categorical columns a filter select is offered for, when a table has them.
FILTERS = ("scenario", "estimator", "method", "mode", "position", "figure", "statistic", "site")
# A scenario board's CSV has these (the real-data table has no env id).
SCENARIO_COLUMNS = {"scenario", "estimator", "mode", "seeds", "ae", "env_id"}


@dataclass(frozen=True)
class Table:
    """One table of a page: a caption, the CSV it came from, and its HTML."""

    caption: str
    csv: str
    html: str
    rows: int


@dataclass
class Page:
    """One page of the site: its file name, title, tables and figures."""

    slug: str
    title: str
    intro: str
    tables: list[Table] = field(default_factory=list)
    images: list[tuple[str, str]] = field(default_factory=list)
    markdown: str | None = None


# ------------------------------------------------------------------ cells


def _number(value: Any) -> float | None:
    try:
        x = float(value)
    except (TypeError, ValueError):
        return None
    return x if math.isfinite(x) else None


def _fmt(x: float) -> str:
    """Integers as such, else two decimals as in the Markdown boards."""
    return str(int(x)) if x == int(x) and abs(x) < 1e6 else f"{x:.2f}"


def _provenance(row: pd.Series, defaults: dict[str, Any]) -> tuple[str, str]:
    """The row's provenance as (short label, full tooltip text)."""
    items = {**defaults, **{k: row[k] for k in PROVENANCE if k in row.index}}
    parts = []
    for k in PROVENANCE:
        v = items.get(k)
        if v is None or (isinstance(v, float) and math.isnan(v)) or v == "":
            continue
        parts.append(f"{k}: {v}")
    return str(items.get("git_revision", "")), "; ".join(parts)


def _table_html(
    frame: pd.DataFrame,
    table_id: str,
    *,
    keys: Sequence[str],
    metrics: Sequence[str],
    provenance: dict[str, Any],
    with_std: bool = False,
    sort: str | None = None,
    headline: Sequence[str] = (),
) -> str:
    """A sortable, filterable ``<table>`` with its controls; metric cells carry ``data-value``."""
    filters = [c for c in FILTERS if c in keys and 1 < frame[c].nunique() <= 40]
    controls = [
        f'<div class="controls" data-table="{table_id}">',
        '<label>filter <input type="search" data-text placeholder="any text"></label>',
    ]
    for col in filters:
        options = "".join(
            f'<option value="{html.escape(str(v))}">{html.escape(str(v))}</option>'
            for v in sorted(frame[col].astype(str).unique())
        )
        controls.append(
            f'<label>{html.escape(col)} <select data-col="{html.escape(col)}">'
            f'<option value="">all</option>{options}</select></label>'
        )
    if len(metrics) > 1:
        options = "".join(f'<option value="{m}">{html.escape(m)}</option>' for m in metrics)
        if headline:
            label = ", ".join(headline)
            options = f'<option value="@headline" selected>{label}</option>' + options
        controls.append(
            f'<label>metric <select data-metric><option value="">all</option>{options}'
            "</select></label>"
        )
    controls.append('<span class="count"></span></div>')

    sort_attr = f' data-sort="{sort}"' if sort else ""
    if headline:
        sort_attr += f' data-headline="{" ".join(headline)}"'
    head = "".join(
        f'<th data-col="{html.escape(k)}" data-kind="key">{html.escape(k)}</th>' for k in keys
    )
    head += "".join(
        f'<th data-col="{html.escape(m)}" data-kind="metric">{html.escape(m)}</th>' for m in metrics
    )
    head += '<th data-col="provenance" data-kind="key">provenance</th>'
    body = []
    for _, row in frame.iterrows():
        label, tooltip = _provenance(row, provenance)
        cells = []
        for k in keys:
            v = row[k]
            text = "" if pd.isna(v) else str(v)
            x = _number(v)
            value = f' data-value="{x!r}"' if x is not None and k == "seeds" else ""
            cells.append(
                f'<td data-col="{html.escape(k)}" class="key"{value}>{html.escape(text)}</td>'
            )
        for m in metrics:
            x = _number(row[m])
            if x is None:
                cells.append(f'<td data-col="{html.escape(m)}" class="na">n/a</td>')
                continue
            text = _fmt(x)
            std = _number(row.get(f"{m}_std")) if with_std else None
            if std is not None and _number(row.get("seeds", 1)) not in (None, 0.0, 1.0):
                text += f' <span class="std">± {_fmt(std)}</span>'
            cells.append(f'<td data-col="{html.escape(m)}" data-value="{x!r}">{text}</td>')
        cells.append(
            '<td data-col="provenance" class="prov">'
            f"<details><summary>{html.escape(label or 'see')}</summary>"
            f"{html.escape(tooltip)}</details></td>"
        )
        body.append(f'<tr title="{html.escape(tooltip)}">{"".join(cells)}</tr>')
    return (
        "".join(controls)
        + f'\n<div class="scroll"><table class="board" id="{table_id}"{sort_attr}>'
        + f"<thead><tr>{head}</tr></thead>\n<tbody>\n"
        + "\n".join(body)
        + "\n</tbody></table></div>"
    )


def _generic(frame: pd.DataFrame) -> tuple[list[str], list[str]]:
    """Key (text) and metric (numeric) columns of a paper or realism CSV."""
    frame = frame.loc[:, [c for c in frame.columns if not str(c).startswith("Unnamed")]]
    keys = [
        c
        for c in frame.columns
        if pd.api.types.is_bool_dtype(frame[c]) or not pd.api.types.is_numeric_dtype(frame[c])
    ]
    keys = [c for c in keys if c not in PROVENANCE and c != "not_judged"]
    metrics = [c for c in frame.columns if c not in keys and c not in PROVENANCE]
    metrics = [c for c in metrics if frame[c].notna().any()]
    return keys, metrics


# ------------------------------------------------------------------ pages


def _read(out: Path, name: str) -> pd.DataFrame | None:
    path = out / f"{name}.csv"
    return pd.read_csv(path) if path.is_file() else None


def _scenario_names(out: Path) -> list[str]:
    """The scenario boards in ``out``: CSVs with the columns of scenario rows."""
    names = []
    for path in sorted(out.glob("*.csv")):
        with path.open() as f:
            header = set(f.readline().strip().split(","))
        if SCENARIO_COLUMNS <= header:
            names.append(path.stem)
    return names


def _scenario_page(out: Path, name: str, provenance: dict[str, Any]) -> Page:
    frame = _read(out, name)
    assert frame is not None
    metrics = [m for m in SCENARIO_METRICS if m in frame.columns and frame[m].notna().any()]
    table = _table_html(
        frame,
        "t-" + name,
        keys=[k for k in SCENARIO_KEYS if k in frame.columns],
        metrics=metrics,
        provenance=provenance,
        with_std=True,
        sort="ae",
        headline=[m for m in HEADLINE if m in metrics],
    )
    page = Page(
        slug=name,
        title=name,
        intro="Position error in metres (time-uniform), mean ± SD over seeds; one row per "
        "estimator and carrying mode. n/a: the estimator does not apply to this site.",
        tables=[Table("estimator × mode", f"{name}.csv", table, len(frame))],
        markdown=f"{name}.md" if (out / f"{name}.md").is_file() else None,
    )
    for suffix, caption in (
        ("cdf", "error CDF per mode"),
        ("tracks", "tracks, first seed: a panel per estimator and mode"),
    ):
        if (out / f"{name}_{suffix}.png").is_file():
            page.images.append((f"{name}_{suffix}.png", caption))
    return page


def _csv_page(
    out: Path,
    slug: str,
    title: str,
    intro: str,
    csvs: Sequence[tuple[str, str]],
    provenance: dict[str, Any],
    *,
    markdown: str | None = None,
    images: Sequence[str] = (),
) -> Page | None:
    if markdown and not (out / markdown).is_file():
        markdown = None
    page = Page(slug=slug, title=title, intro=intro, markdown=markdown)
    for name, caption in csvs:
        frame = _read(out, name)
        if frame is None:
            continue
        keys, metrics = _generic(frame)
        if name == "real_data":
            keys, metrics = (
                [k for k in SCENARIO_KEYS if k in frame.columns],
                [m for m in SCENARIO_METRICS if m in frame.columns and frame[m].notna().any()],
            )
        html_table = _table_html(
            frame,
            "t-" + name,
            keys=keys,
            metrics=metrics,
            provenance=provenance,
            with_std=name == "real_data",
        )
        page.tables.append(Table(caption, f"{name}.csv", html_table, len(frame)))
    if not page.tables:
        return None
    page.images += [(f"{n}.png", n) for n in images if (out / f"{n}.png").is_file()]
    return page


def _pages(out: Path, provenance: dict[str, Any]) -> list[Page]:
    pages = [_scenario_page(out, name, provenance) for name in _scenario_names(out)]
    others = [
        _csv_page(
            out,
            "han2023",
            "Han2023 tables",
            "Han et al. 2023 (magnetic/PDR fusion): each table beside the paper's "
            "numbers (paper_* columns). The reading of each table is in han2023.md.",
            [
                ("han2023_table1", "Table 1: heading error of the Kalman variants (°)"),
                ("han2023_table2", "Table 2: BP and GM fingerprint error (m)"),
                ("han2023_tables3_4", "Tables 3-4: GM and GML localization (m)"),
            ],
            provenance,
            markdown="han2023.md",
            images=("han2023_fig13_heading_cdf", "han2023_fig14_convergence"),
        ),
        _csv_page(
            out,
            "chen2022",
            "Chen2022 tables",
            "Chen et al. 2022 (WiFi/magnetic particle filters): each table beside the "
            "paper's numbers (paper_* columns). The reading of each table is in chen2022.md.",
            [
                ("chen2022_table1", "Table 1: the lab (m)"),
                ("chen2022_table2", "Table 2: the office (m)"),
                ("chen2022_figures", "Figures 8, 10 and 23: error CDF readings (m)"),
            ],
            provenance,
            markdown="chen2022.md",
            images=("chen2022_fig8_cdf", "chen2022_fig10_cdf", "chen2022_fig23_cdf"),
        ),
        _csv_page(
            out,
            "realism",
            "Realism",
            "Simulated phone motion and environment beside real recordings, statistic by "
            "statistic: the real range (real_low … real_high) and each simulated site.",
            [
                ("realism_motion", "phone motion"),
                ("realism_environment", "magnetic field, WiFi and light"),
            ],
            provenance,
            markdown="realism.md",
            images=("realism_motion",),
        ),
        _csv_page(
            out,
            "robustness",
            "Robustness",
            "Every estimator under every sensor fault: whether it crashed, its mean error "
            "under the fault over the fault-free one (ratio), and the time to recover after "
            "a fault that ends (s; inf: not before the walk's end).",
            [("robustness", "estimator × fault")],
            provenance,
            markdown="robustness.md",
            images=("robustness",),
        ),
        _csv_page(
            out,
            "real_data",
            "Real data",
            "Real recordings: Indoor Location Competition 2.0 traces scored at the "
            "surveyor's waypoints (m, mean ± SD over traces), and Han2023's step detector "
            "on the Oxford step-counter walks (error in % of the true steps).",
            [
                ("real_data", "ILC 2020 site 1 floor F1"),
                ("step_counts_real", "step counts (Oxford step-counter walks)"),
            ],
            provenance,
            markdown="real_data.md",
        ),
    ]
    return pages + [p for p in others if p is not None]


def _best_rows(out: Path, names: Sequence[str]) -> pd.DataFrame:
    """Per scenario and mode, the row with the lowest AE."""
    rows = []
    for name in names:
        frame = _read(out, name)
        if frame is None or "ae" not in frame.columns:
            continue
        frame = frame[frame["ae"].notna()]
        for _, group in frame.groupby("mode", sort=False):
            rows.append(group.loc[group["ae"].idxmin()])
    return pd.DataFrame(rows).reset_index(drop=True)


# ------------------------------------------------------------------ writing

CSS = """
body{font:15px/1.45 system-ui,sans-serif;margin:0;color:#1d232a;background:#fafbfc}
nav{background:#1f3a5f;padding:.6em 1.2em}nav a{color:#fff;margin-right:1.1em;text-decoration:none}
nav a.here{font-weight:bold;text-decoration:underline}
main{padding:1em 1.5em;max-width:1400px}h1{margin:.2em 0 .3em}
.controls{display:flex;flex-wrap:wrap;gap:.4em 1.2em;align-items:center;margin:.5em 0}
.controls .count{color:#667}
table.board{border-collapse:collapse;background:#fff;font-variant-numeric:tabular-nums}
table.board th,table.board td{border:1px solid #d4d9df;padding:.25em .55em;text-align:right}
table.board th[data-kind=key],table.board td.key{text-align:left}
table.board th{background:#e9eef4;cursor:pointer;user-select:none}
table.board td{white-space:nowrap}.scroll{overflow-x:auto}
table.board th.asc::after{content:" ▲"}table.board th.desc::after{content:" ▼"}
table.board tbody tr:nth-child(even){background:#f4f6f8}
table.board tbody tr:hover{background:#fff6d8}
td.na{color:#99a}.std{color:#778;font-size:.85em}
table.board td.prov{text-align:left;font-size:.85em;white-space:normal}
td.prov details{max-width:22em}
td.prov summary{cursor:pointer;font-family:monospace;white-space:nowrap}
.hidden{display:none}figure{margin:1em 0}figure img{max-width:100%;border:1px solid #d4d9df}
ul.pages li{margin:.2em 0}.meta{color:#667;font-size:.9em}
"""

# Sorting, filtering and the metric selector; sets data-ready on <body> when done.
SCRIPT = """
(function(){
  function val(td){
    if(!td){return null;}
    var v=td.getAttribute('data-value');
    return v===null?null:parseFloat(v);
  }
  function text(td){return td?td.textContent.trim().toLowerCase():'';}
  function sortBy(table,col,dir){
    var ths=table.tHead.rows[0].cells,idx=-1;
    for(var i=0;i<ths.length;i++){
      ths[i].classList.remove('asc','desc');
      if(ths[i].getAttribute('data-col')===col){idx=i;}
    }
    if(idx<0){return;}
    ths[idx].classList.add(dir>0?'asc':'desc');
    var body=table.tBodies[0],rows=Array.prototype.slice.call(body.rows);
    rows.sort(function(a,b){
      var x=val(a.cells[idx]),y=val(b.cells[idx]);
      if(x!==null||y!==null){
        if(x===null){return 1;}if(y===null){return -1;}
        return dir*(x-y);
      }
      return dir*text(a.cells[idx]).localeCompare(text(b.cells[idx]));
    });
    rows.forEach(function(r){body.appendChild(r);});
    table.setAttribute('data-sorted',col+(dir>0?':asc':':desc'));
  }
  function apply(table,controls){
    var q=controls.querySelector('[data-text]').value.trim().toLowerCase();
    var sels=controls.querySelectorAll('select[data-col]');
    var ths=table.tHead.rows[0].cells,shown=0,rows=table.tBodies[0].rows;
    for(var r=0;r<rows.length;r++){
      var row=rows[r],ok=!q||row.textContent.toLowerCase().indexOf(q)>=0;
      for(var s=0;s<sels.length&&ok;s++){
        var want=sels[s].value,col=sels[s].getAttribute('data-col');
        if(!want){continue;}
        for(var c=0;c<ths.length;c++){
          if(ths[c].getAttribute('data-col')===col){ok=row.cells[c].textContent.trim()===want;}
        }
      }
      row.classList.toggle('hidden',!ok);
      if(ok){shown++;}
    }
    table.setAttribute('data-visible',String(shown));
    controls.querySelector('.count').textContent=shown+' of '+rows.length+' rows';
  }
  function showMetric(table,metric){
    var shown=metric==='@headline'?(table.getAttribute('data-headline')||'').split(' '):[metric];
    var metrics={};
    table.querySelectorAll('th[data-kind=metric]').forEach(function(th){
      metrics[th.getAttribute('data-col')]=true;
    });
    table.querySelectorAll('th[data-col],td[data-col]').forEach(function(el){
      var col=el.getAttribute('data-col');
      if(metrics[col]){el.classList.toggle('hidden',!!metric&&shown.indexOf(col)<0);}
    });
    if(metric&&metric!=='@headline'){sortBy(table,metric,1);}
  }
  document.querySelectorAll('table.board').forEach(function(table){
    var controls=document.querySelector('.controls[data-table="'+table.id+'"]');
    var state={col:null,dir:1};
    Array.prototype.forEach.call(table.tHead.rows[0].cells,function(th){
      th.addEventListener('click',function(){
        var col=th.getAttribute('data-col');
        state.dir=state.col===col?-state.dir:1;state.col=col;
        sortBy(table,col,state.dir);
      });
    });
    if(controls){
      controls.querySelectorAll('input,select[data-col]').forEach(function(el){
        el.addEventListener('input',function(){apply(table,controls);});
      });
      var metric=controls.querySelector('select[data-metric]');
      if(metric){
        metric.addEventListener('change',function(){showMetric(table,metric.value);});
        showMetric(table,metric.value);
      }
      apply(table,controls);
    }
    var first=table.getAttribute('data-sort');
    if(first){state.col=first;sortBy(table,first,1);}
  });
  document.body.setAttribute('data-ready','1');
})();
"""


def _document(title: str, nav: str, content: str) -> str:
    return (
        '<!doctype html>\n<html lang="en"><head><meta charset="utf-8">\n'
        '<meta name="viewport" content="width=device-width,initial-scale=1">\n'
        f"<title>{html.escape(title)} · indoorsim leaderboards</title>\n"
        f"<style>{CSS}</style></head>\n"
        f'<body data-ready="0">\n<nav>{nav}</nav>\n<main>\n{content}\n</main>\n'
        f"<script>{SCRIPT}</script>\n</body></html>\n"
    )


def _nav(pages: Sequence[Page], here: str) -> str:
    links = [("index", "index", "Overview")] + [(p.slug, p.slug, p.title) for p in pages]
    return "".join(
        f'<a href="{slug}.html"{" class=here" if slug == here else ""}>{html.escape(t)}</a>'
        for slug, _, t in links
    )


def _page_html(page: Page, pages: Sequence[Page], meta: str) -> str:
    parts = [f"<h1>{html.escape(page.title)}</h1>", f"<p>{html.escape(page.intro)}</p>"]
    files = [page.markdown] if page.markdown else []
    files += [t.csv for t in page.tables]
    parts.append(
        '<p class="meta">'
        + ", ".join(f'<a href="../{f}">{f}</a>' for f in files)
        + f" (every column). {meta}</p>"
    )
    for table in page.tables:
        parts += [f"<h2>{html.escape(table.caption)}</h2>", table.html]
    for png, caption in page.images:
        parts.append(
            f'<figure><img src="../{png}" alt="{html.escape(caption)}" loading="lazy">'
            f"<figcaption>{html.escape(caption)}</figcaption></figure>"
        )
    return _document(page.title, _nav(pages, page.slug), "\n".join(parts))


def write_site(out: Path) -> list[Path]:
    """Write ``out/site/index.html`` and a page per board from the CSVs in ``out``.

    Args:
        out: a leaderboards folder as :func:`~indoorsim.benchmark.leaderboard.run_leaderboard`
            writes it (only the boards whose CSVs are present get a page).

    Returns the pages written, the index first.
    """
    prov_file = out / "provenance.json"
    doc = json.loads(prov_file.read_text()) if prov_file.is_file() else {}
    config = doc.get("config", {})
    provenance = {
        "git_revision": doc.get("git_revision", ""),
        "package_version": doc.get("package_version", ""),
        "device": config.get("device", ""),
        "window_s": config.get("window_s", ""),
    }
    meta = (
        f"Generated from revision {doc.get('git_revision', '?')}, "
        f"package {doc.get('package_version', '?')}."
    )
    pages = _pages(out, provenance)
    site = out / "site"
    site.mkdir(parents=True, exist_ok=True)
    written = []
    for page in pages:
        path = site / f"{page.slug}.html"
        path.write_text(_page_html(page, pages, meta))
        written.append(path)

    best = _best_rows(out, [*_scenario_names(out), "real_data"])
    parts = [
        "<h1>indoorsim leaderboards</h1>",
        "<p>Smartphone indoor positioning estimators scored against the simulator's exact "
        "ground truth, and the papers' experiments reproduced. Click a column header to "
        "sort; filter by text, estimator or mode; hover a row for its provenance.</p>",
        f'<p class="meta">{meta}'
        + (
            ' Markdown: <a href="../README.md">README.md</a>.'
            if (out / "README.md").is_file()
            else ""
        )
        + "</p>",
        '<ul class="pages">',
        *(
            f'<li><a href="{p.slug}.html">{html.escape(p.title)}</a>: '
            + ", ".join(f"{html.escape(t.caption)} ({t.rows} rows)" for t in p.tables)
            + "</li>"
            for p in pages
        ),
        "</ul>",
    ]
    if len(best):
        parts += [
            "<h2>Best estimator per scenario and mode (lowest AE)</h2>",
            _table_html(
                best,
                "t-best",
                keys=["scenario", "mode", "estimator", "seeds"],
                metrics=[m for m in HEADLINE if m in best.columns],
                provenance=provenance,
                with_std=True,
            ),
        ]
    index = site / "index.html"
    index.write_text(_document("Overview", _nav(pages, "index"), "\n".join(parts)))
    return [index, *written]
