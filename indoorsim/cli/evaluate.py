"""``indoorsim evaluate`` and ``indoorsim leaderboard``: estimators scored by the protocol.

``evaluate`` scores one estimator on one scenario (or a real recording) and
can fail a CI run on a metric threshold; ``leaderboard`` regenerates the
leaderboard tables, CSVs, plots and the static site (``--site-only``: the site alone).
"""

from __future__ import annotations

import argparse
import math
import sys
from pathlib import Path
from typing import TYPE_CHECKING, Any

from indoorsim.cli.args import (
    CliError,
    EstimatorNamesFormatter,
    add_board_folders,
    check_folder,
    check_out,
    device_profile,
    estimator_options,
    mode_schedule,
    positive,
    route_or_first,
    working,
)

if TYPE_CHECKING:
    from indoorsim.benchmark.evaluation import WalkResult
    from indoorsim.cli.args import Subparsers

__all__ = ["add_evaluate", "add_leaderboard"]


# -------------------------------------------------------------------- evaluate


def _thresholds(text: str) -> dict[str, float]:
    """``ae=1.5,cep95=3`` → ``{"ae": 1.5, "cep95": 3.0}`` (metric names as in the CSVs)."""
    from indoorsim.benchmark.metrics import SUMMARY_KEYS

    out: dict[str, float] = {}
    for item in text.split(","):
        name, sep, value = item.partition("=")
        name = name.strip()
        if not sep or name not in SUMMARY_KEYS:
            raise argparse.ArgumentTypeError(
                f"{item!r}: expected METRIC=VALUE with METRIC one of {', '.join(SUMMARY_KEYS)}"
            )
        try:
            limit = float(value)
        except ValueError:
            raise argparse.ArgumentTypeError(f"{item!r}: {value!r} is not a number") from None
        if not math.isfinite(limit):
            # No metric exceeds inf, and NaN compares false with everything.
            raise argparse.ArgumentTypeError(f"{item!r}: threshold must be a finite number")
        out[name] = limit
    return out


def add_evaluate(subparsers: Subparsers) -> None:
    """Declare ``indoorsim evaluate``."""
    parser = subparsers.add_parser(
        "evaluate",
        help="score one estimator on a scenario (or a real recording)",
        description="Run an estimator through the evaluation protocol: site context and "
        "training walks, then one test walk per seed. Writes per walk estimates.csv "
        "(t, x, y, true_x, true_y) and metrics.csv, and a summary.csv. With --fail-above "
        "the exit status is 3 when any named metric (mean over seeds) is worse than its "
        "threshold: the CI use case. An --out that exists is refused, as simulate refuses "
        "it, unless --overwrite; the results are written all at once when they are complete.",
        formatter_class=EstimatorNamesFormatter,
    )
    parser.add_argument(
        "--estimator",
        required=True,
        metavar="NAME[:K=V,...]",
        help="a registered estimator ({estimators}) or package.module:Class, with "
        "constructor options after a colon, values read as JSON: "
        "chen2022-cpf:likelihood=gaussian,n_particles=500 or learned-io:checkpoint=DIR "
        "(a folder written by indoorsim train). `indoorsim estimators` says what each "
        "needs, `indoorsim estimators NAME` lists its options",
    )
    source = parser.add_mutually_exclusive_group(required=True)
    source.add_argument("--scenario", metavar="NAME_OR_PATH", help="a scenario to simulate")
    source.add_argument(
        "--recording",
        type=Path,
        metavar="PATH",
        help="a recording (indoorsim folder or a real log) scored at its true positions",
    )
    parser.add_argument("--mode", default="handheld", help="carrying mode (default handheld)")
    parser.add_argument(
        "--route",
        default=None,
        metavar="NAME",
        help="test route (default: the scenario's first; indoorsim scenarios NAME lists them)",
    )
    parser.add_argument(
        "--seeds", type=positive(int), default=3, metavar="N", help="test seeds 0..N-1"
    )
    parser.add_argument("--device", default="nexus_5x", help="walking phone (default nexus_5x)")
    parser.add_argument(
        "--survey-device", default="honor_50", help="survey phone (default honor_50)"
    )
    parser.add_argument(
        "--window", type=positive(float), default=1.0, metavar="S", help="window length, s"
    )
    parser.add_argument(
        "--train-routes",
        choices=("other", "same"),
        default="other",
        help="routes of the labelled training walks: the scenario's other routes "
        "(default) or the test route by other seeds",
    )
    parser.add_argument("--out", type=Path, required=True, metavar="DIR")
    parser.add_argument(
        "--overwrite",
        action="store_true",
        help="replace an earlier evaluation's results at --out, the whole folder (its "
        "per-seed folders too, so that runs never mix)",
    )
    parser.add_argument(
        "--export",
        choices=("tum",),
        help="also write each walk's estimate.tum and truth.tum beside its estimates.csv, "
        "for evo (evo_ape tum truth.tum estimate.tum) and other SLAM tools. TUM format: one "
        "pose per line, 'timestamp tx ty tz qx qy qz qw', space-separated, no header: the "
        "rows of estimates.csv (the estimate at each window's end, t, x, y; the truth "
        "true_x, true_y at the same times), z = 0. Orientation: a turn about +z by the "
        "estimator's heading where it exposes one, else the identity (0 0 0 1); the "
        "truth's is the true walking direction (the identity for a real log, whose rows "
        "are its truth times, with the estimates interpolated to them)",
    )
    parser.add_argument(
        "--fault",
        action="append",
        default=[],
        metavar="NAME[:K=V,...]",
        help="a sensor fault applied to each test walk (or to --recording), repeatable, "
        "in order: e.g. bias_jump:stream=accel,t0=5,vector=0.3/0/0 or "
        "dropout:streams=accel/gyro,p=0.2. Numbers are floats; lists (streams, x/y/z "
        "vectors) separate items with / or ;. An unknown NAME is refused with the list of "
        "faults, an unknown key with the fault's parameters",
    )
    parser.add_argument(
        "--fail-above",
        type=_thresholds,
        default={},
        metavar="M=V,...",
        help="exit 3 if any of these metrics exceeds its value, e.g. ae=1.5,cep95=3",
    )
    parser.set_defaults(handler=_run_evaluate)


def _run_evaluate(args: argparse.Namespace) -> int:
    import json

    import pandas as pd

    from indoorsim.benchmark import evaluation, leaderboard
    from indoorsim.io.atomic import write_folder
    from indoorsim.io.faults import (
        FaultError,
        WalkFault,
        apply_faults,
        parse_fault,
        walk_arguments,
    )
    from indoorsim.io.recording import MissingStreamError, Recording, RecordingError

    check_out(args.out, overwrite=args.overwrite, what="evaluation")
    if args.overwrite and args.out.is_dir() and any(args.out.iterdir()):
        if not _is_evaluation(args.out):
            # write_folder would refuse it too, but only after the slow work.
            raise CliError(
                f"--out {args.out}: not an earlier evaluation (no summary.csv); "
                "refusing to replace it"
            )
    faults = []
    for spec in args.fault:
        try:
            faults.append(parse_fault(spec))
        except FaultError as err:
            raise CliError(f"--fault {spec}: {err}") from None
    name, params = estimator_options(args.estimator)
    # Checking the options imported every estimator.
    from indoorsim.estimators.base import NotApplicableError

    # --out is written only once there are results, all at once (write_folder).
    if args.recording is not None:
        try:
            rec = Recording.load(args.recording)
        except (RecordingError, OSError) as err:
            raise CliError(f"--recording {args.recording}: {err}") from None
        walk_faults = [f.name for f in faults if isinstance(f, WalkFault)]
        if walk_faults:
            raise CliError(
                f"--fault {', '.join(walk_faults)}: changes how a walk is simulated, "
                "which a --recording already is; use it with --scenario"
            )
        try:
            rec = apply_faults(rec, faults, seed=0)
        except FaultError as err:
            raise CliError(f"--fault: {err}") from None
        try:
            with working(f"evaluating {args.estimator}"):
                walk = evaluation.evaluate_recording(name, rec, window_s=args.window, params=params)
        except NotApplicableError as err:
            raise CliError(f"--estimator {args.estimator}: not applicable here: {err}") from None
        except evaluation.EstimatorError as err:
            raise _estimator_failed(name, params, err) from err
        except (MissingStreamError, ValueError) as err:
            # A log without the truth or waypoints that scoring needs.
            raise CliError(f"--recording {args.recording}: cannot be scored: {err}") from None
        summary = pd.DataFrame(
            [{"estimator": name, "params": json.dumps(params, sort_keys=True), **walk.metrics}]
        )

        def write(folder: Path) -> None:
            walk.estimates.to_csv(folder / "estimates.csv", index=False)
            if args.export == "tum":
                _export_tum(walk, folder)
            summary.to_csv(folder / "summary.csv", index=False)
    else:
        from indoorsim.scenario.load import load_site

        site = load_site(args.scenario)
        mode_schedule(args.mode, one_mode=True)
        device_profile(args.device)
        device_profile(args.survey_device)
        try:
            walk_arguments(faults, args.mode, args.device)  # a walk fault that changes nothing
        except FaultError as err:
            raise CliError(f"--fault: {err}") from None
        route = route_or_first(site, args.route)  # last: it says which route when defaulting
        from tqdm import tqdm

        try:
            with tqdm(total=args.seeds, desc=name, disable=None, file=sys.stderr) as bar:
                ev = evaluation.evaluate(
                    name,
                    site,
                    mode=args.mode,
                    seeds=tuple(range(args.seeds)),
                    route=route,
                    device=args.device,
                    survey_device=args.survey_device,
                    window_s=args.window,
                    train_routes=args.train_routes,
                    params=params,
                    faults=faults,
                    progress=lambda _msg: bar.update(1),  # called as each seed's walk starts
                )
        except evaluation.EstimatorError as err:
            raise _estimator_failed(name, params, err) from err
        except FaultError as err:
            raise CliError(f"--fault: {err}") from None
        if ev.note:
            raise CliError(f"--estimator {args.estimator}: not applicable here: {ev.note}")
        summary = pd.DataFrame([ev.row()])

        def write(folder: Path) -> None:
            leaderboard.write_walks(ev, folder)
            if args.export == "tum":
                for walk in ev.walks:
                    # The folder leaderboard.write_walks wrote the walk's estimates.csv in.
                    _export_tum(walk, folder / f"{ev.scenario}_{ev.mode}_{name}_seed{walk.seed}")
            summary.to_csv(folder / "summary.csv", index=False)

    write_folder(
        args.out,
        write,
        overwrite=args.overwrite,
        is_ours=_is_evaluation,
        what="evaluation",
    )
    shown = [c for c in ("ae", "rmse", "me", "cep50", "cep95") if c in summary]
    print(summary[["estimator", *shown]].to_string(index=False, float_format=lambda v: f"{v:.2f}"))
    worse = {
        k: float(summary[k].iloc[0])
        for k, limit in args.fail_above.items()
        if not float(summary[k].iloc[0]) <= limit  # NaN counts as worse
    }
    if worse:
        for k, v in worse.items():
            print(f"indoorsim: {k} = {v:.3f} exceeds {args.fail_above[k]:g}", file=sys.stderr)
        return 3
    return 0


def _is_evaluation(folder: Path) -> bool:
    """Whether ``folder`` holds the results of an earlier ``evaluate`` (its summary.csv)."""
    return (folder / "summary.csv").is_file()


def _estimator_failed(name: str, params: dict[str, Any], err: Exception) -> CliError:
    """An estimator that raised or gave no position (an ``EstimatorError``), as one line.

    A checkpoint that does not load (a ``CheckpointError`` from ``fit``) is
    said as the option's problem; the traceback stays in the chain for ``--debug``.
    """
    from indoorsim.estimators.nn.inertial import CheckpointError

    if isinstance(err.__cause__, CheckpointError):
        option = "option checkpoint: " if "checkpoint" in params else ""
        return CliError(f"--estimator {name}: {option}{err.__cause__}")
    return CliError(str(err))


def _export_tum(walk: WalkResult, folder: Path) -> None:
    """``estimate.tum`` and ``truth.tum`` of one walk in ``folder`` (see ``--export``)."""
    from indoorsim.io.tum import write_tum

    est = walk.estimates
    t = est["t"].to_numpy(dtype=float)
    try:
        write_tum(folder / "estimate.tum", t, est[["x", "y"]].to_numpy(), heading=walk.heading)
        write_tum(
            folder / "truth.tum",
            t,
            est[["true_x", "true_y"]].to_numpy(),
            heading=walk.true_heading,
        )
    except ValueError as err:  # times that do not increase (a real log's)
        raise CliError(f"--export tum: {err}") from None


# ----------------------------------------------------------------- leaderboard


def add_leaderboard(subparsers: Subparsers) -> None:
    """Declare ``indoorsim leaderboard``."""
    parser = subparsers.add_parser(
        "leaderboard",
        help="regenerate the leaderboards (tables, CSVs, plots)",
        description="Evaluate the estimators on the bundled paper scenarios in every carrying "
        "mode over several seeds, and write per scenario a Markdown table, a CSV with "
        "provenance, CDF and track plots, plus the real-data table, README.md and a static "
        "site (DIR/site/index.html: sortable, filterable tables; no network needed).",
        formatter_class=EstimatorNamesFormatter,
    )
    parser.add_argument(
        "--scenario", action="append", metavar="NAME", help="only these scenarios (repeatable)"
    )
    parser.add_argument(
        "--estimator",
        action="append",
        metavar="NAME",
        help="only these estimators (repeatable): {estimators}, or package.module:Class",
    )
    parser.add_argument("--quick", action="store_true", help="one seed, two modes, no real data")
    parser.add_argument(
        "--site-only",
        action="store_true",
        help="only rebuild the static site (DIR/site/) from the CSVs already in --out",
    )
    parser.add_argument(
        "--robustness-only",
        action="store_true",
        help="only regenerate the robustness board (every estimator under every sensor "
        "fault: DIR/robustness.md), then README.md and the site from the tables in --out",
    )
    parser.add_argument(
        "--sim-to-real-only",
        action="store_true",
        help="only regenerate DIR/sim_to_real.md (what is tuned on simulation alone, "
        "run on the real recordings), then README.md and the site",
    )
    add_board_folders(
        parser,
        "the folder of real recordings for the real-data tables (default: "
        "$INDOORSIM_REALDATA, else ../shared/realdata beside the repository)",
    )
    parser.set_defaults(handler=_run_leaderboard)


def _run_leaderboard(args: argparse.Namespace) -> int:
    import dataclasses

    from tqdm import tqdm

    from indoorsim.benchmark import leaderboard
    from indoorsim.benchmark.evaluation import EstimatorError
    from indoorsim.scenario.load import UnknownScenarioError, bundled_scenarios

    check_folder(args.out)
    if args.site_only:
        from indoorsim.benchmark.results_site import write_site

        if not any(args.out.glob("*.csv")):
            raise CliError(f"--out {args.out}: no leaderboard CSVs to build the site from")
        pages = write_site(args.out)
        print(f"wrote {len(pages)} pages into {args.out / 'site'}/")
        return 0
    known = bundled_scenarios()
    for name in args.scenario or ():
        if name not in known:
            raise CliError(f"--scenario {name}: {UnknownScenarioError(name, known)}")
    for spec in args.estimator or ():
        # A registered name or a module:Class plug-in, as for evaluate; its defaults only.
        _, params = estimator_options(spec)
        if params:
            raise CliError(
                f"--estimator {spec}: leaderboard rows use each estimator's defaults; "
                "give options to indoorsim evaluate"
            )
    config = (
        leaderboard.BoardConfig.quick(args.scenario)
        if args.quick
        else leaderboard.BoardConfig(
            **({"scenarios": tuple(args.scenario)} if args.scenario else {})
        )
    )
    if args.estimator:
        config = dataclasses.replace(
            config, estimators=tuple(args.estimator), robustness_estimators=None
        )
    if args.robustness_only:
        from indoorsim.benchmark.results_site import write_site

        with tqdm(desc="robustness", disable=None, file=sys.stderr) as bar:
            try:
                leaderboard.write_robustness_board(
                    config,
                    args.out,
                    progress=lambda msg: (bar.set_postfix_str(msg), bar.update(1)),
                )
            except EstimatorError as err:
                raise CliError(str(err)) from err
        leaderboard.write_readme(args.out, leaderboard.tables_on_disk(args.out, config))
        write_site(args.out)
        print(f"wrote {args.out / 'robustness.md'}")
        return 0
    if args.sim_to_real_only:
        from indoorsim.benchmark.results_site import write_site
        from indoorsim.benchmark.sim_to_real import write_sim_to_real
        from indoorsim.util.provenance import realdata_dir

        real = realdata_dir(args.realdata)
        if not real.is_dir():
            raise CliError(f"no real-data folder at {real}: give --realdata")
        args.out.mkdir(parents=True, exist_ok=True)
        with tqdm(desc="sim-to-real", disable=None, file=sys.stderr) as bar:
            elapsed = write_sim_to_real(
                args.out, real, progress=lambda msg: (bar.set_postfix_str(msg), bar.update(1))
            )
        leaderboard.write_readme(args.out, leaderboard.tables_on_disk(args.out, config))
        write_site(args.out)
        print(f"wrote {args.out / 'sim_to_real.md'} in {elapsed:.1f} s")
        return 0
    timings: dict[str, float] = {}
    try:
        with tqdm(desc="leaderboard", disable=None, file=sys.stderr) as bar:
            tables = leaderboard.run_leaderboard(
                config,
                args.out,
                progress=lambda msg: (bar.set_postfix_str(msg), bar.update(1)),
                realdata=args.realdata,
                timings=timings,
            )
    except EstimatorError as err:
        raise CliError(str(err)) from err
    for name, table in tables.items():
        print(f"\n## {name}\n\n{leaderboard.markdown_table(table)}")
    for part, seconds in timings.items():
        print(f"\n{part}: regenerated in {seconds:.1f} s")
    print(f"\nwrote {args.out}/")
    return 0
