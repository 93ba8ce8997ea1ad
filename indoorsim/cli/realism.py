"""``indoorsim realism``: simulated phones and buildings measured beside real recordings.

Simulates walks in every carrying mode over bundled and generated sites and
computes, with the same functions as on real logs, the motion, magnetic, WiFi
and light statistics of :mod:`indoorsim.benchmark.realism`; writes ``realism.md`` (real range,
simulated value, inside or outside, per statistic and mode), the CSVs and the
overlay plot.
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path
from typing import TYPE_CHECKING

from indoorsim.cli.args import (
    CliError,
    add_board_folders,
    check_folder,
    device_profile,
    mode_schedule,
    seed_number,
)

if TYPE_CHECKING:
    from indoorsim.cli.args import Subparsers

__all__ = ["add_calibrate", "add_realism"]


def add_realism(subparsers: Subparsers) -> None:
    parser = subparsers.add_parser(
        "realism",
        help="compare simulated phones and buildings with real recordings",
        description="Simulate walks in every carrying mode over bundled and generated sites "
        "and compare their motion statistics (shape, spread and spectra of |a|, gyro RMS, "
        "heading jitter and drift), and along handheld walks the magnetic field (its spectrum "
        "against distance walked), the WiFi scans and the light sensor, with those of real "
        "phone logs, by the same functions. "
        "Writes realism.md, the CSVs and realism_motion.png.",
    )
    add_board_folders(
        parser,
        "measure the real logs in this folder instead of reading the committed table "
        "of their statistics",
    )
    parser.add_argument(
        "--refresh-reference",
        action="store_true",
        help="measure the real logs (--realdata, $INDOORSIM_REALDATA or ../shared/realdata) "
        "and write their statistics over the committed table; a data set not in the folder "
        "keeps its committed rows (the Tyrex attitude benchmark's walks are measured from "
        "a copy of its repository at <folder>/tyrex-attitude)",
    )
    parser.add_argument(
        "--seeds",
        type=seed_number,
        default=None,
        metavar="N",
        help="seeds per site and mode (default: as many as the leaderboard takes)",
    )
    parser.add_argument(
        "--mode",
        action="append",
        metavar="NAME",
        help="only these carrying modes (repeatable; default: every modelled one)",
    )
    parser.add_argument("--device", default="nexus_5x", metavar="NAME", help="simulated phone")
    parser.set_defaults(handler=_run_realism)


def _run_realism(args: argparse.Namespace) -> int:
    from tqdm import tqdm

    from indoorsim.benchmark.realism.reference import MODELLED_MODES
    from indoorsim.benchmark.realism.report import RealismConfig, run_realism

    check_folder(args.out)
    if args.seeds is not None and args.seeds < 1:
        raise CliError("--seeds must be at least 1")
    if args.realdata is not None and not args.realdata.is_dir():
        raise CliError(f"--realdata {args.realdata}: no such folder")
    modes = tuple(args.mode or MODELLED_MODES)
    for mode in modes:
        mode_schedule(mode, one_mode=True)
    device_profile(args.device)
    seeds = RealismConfig().seeds if args.seeds is None else tuple(range(args.seeds))
    config = RealismConfig(modes=modes, seeds=seeds, device=args.device)
    with tqdm(desc="realism", disable=None, file=sys.stderr) as bar:
        table = run_realism(
            args.out,
            config=config,
            realdata=args.realdata,
            refresh_reference=args.refresh_reference,
            progress=lambda msg: (bar.set_postfix_str(msg), bar.update(1)),
        )
    judged = table.dropna(subset=["sites_inside"])
    inside = int((judged["sites_inside"] == judged["sites"]).sum())
    print(f"{inside} of {len(judged)} statistics inside their real range on every site")
    print(f"wrote {args.out}/realism.md")
    return 0


def add_calibrate(subparsers: Subparsers) -> None:
    parser = subparsers.add_parser(
        "calibrate",
        help="fit a device profile and a walker to a recording (a digital twin)",
        description="Fit a device profile (rates, timestamp jitter and gaps, white noise "
        "from the still parts, gyro bias, the magnetometer's residual hard iron where "
        "the walk turns far enough, light reporting, WiFi scan interval and "
        "threshold) and walker parameters (step rate, speed and step length from the "
        "waypoints, height, standing time; through the carrying mode, --mode or the "
        "recording's own, the vigour: bounce, loading peak and heel strikes) to a real "
        "or simulated recording. Writes YAML "
        "with device: and walker: sections, which --device FILE and --walker FILE of "
        "simulate read; figures a recording cannot show come from --base.",
    )
    parser.add_argument(
        "recording",
        type=Path,
        metavar="RECORDING",
        help="a recording folder or a real log (any format indoorsim reads)",
    )
    parser.add_argument("--out", type=Path, required=True, metavar="FILE", help="YAML to write")
    parser.add_argument(
        "--name", default=None, metavar="NAME", help="the profile's name (default: the file's)"
    )
    parser.add_argument(
        "--base",
        default="mid_grade",
        metavar="DEVICE",
        help="profile whose figures stand where the recording shows nothing (default mid_grade)",
    )
    parser.add_argument(
        "--mode",
        default=None,
        metavar="MODE",
        help="carrying mode the recording was made in (handheld, calling, dangling, "
        "pocketed, or a plug-in's), through which the walker's vigour is fitted "
        "(default: the recording's own, where it names one; else not fitted)",
    )
    parser.add_argument("--overwrite", action="store_true", help="replace an existing --out")
    parser.set_defaults(handler=_run_calibrate)


def _run_calibrate(args: argparse.Namespace) -> int:
    import time

    from indoorsim.benchmark.realism.calibrate import (
        CalibrationError,
        calibrate,
        write_calibration,
    )
    from indoorsim.benchmark.realism.vigour import FIGURES
    from indoorsim.io.recording import Recording, RecordingError

    if args.out.exists() and not args.overwrite:
        raise CliError(f"--out {args.out}: exists; pass --overwrite to replace it")
    if args.out.suffix not in (".yaml", ".yml"):
        raise CliError(f"--out {args.out}: must end in .yaml or .yml (--device reads those)")
    base = device_profile(args.base)
    start = time.perf_counter()
    try:
        rec = Recording.load(args.recording)
    except (RecordingError, OSError) as err:
        raise CliError(f"{args.recording}: {err}") from None
    try:
        cal = calibrate(rec, name=args.name or args.out.stem, base=base, mode=args.mode)
    except CalibrationError as err:
        where = "--mode" if args.mode is not None and "mode" in str(err) else args.recording
        raise CliError(f"{where}: {err}") from None
    write_calibration(cal, args.out)
    elapsed = time.perf_counter() - start
    m = cal.measured
    lines = [f"wrote {args.out} in {elapsed:.2f} s"]
    for key in (
        "accel.rate_hz",
        "accel.noise_density",
        "gyro.noise_density",
        "mag.noise_sigma_uT",
        "timestamp_jitter_frac",
        "step_rate_hz",
        "speed_mps",
        "step_length_m",
        "height_m",
        "still_s",
    ):
        if key in m:
            lines.append(f"  {key}: {m[key]:.4g}")
    if "acc_step_amplitude" in m:
        w = cal.walker
        lines.append(
            f"  walker vigour: bounce_fraction {w.bounce_fraction:.3g}, loading_width "
            f"{w.loading_width[0]:.3g}, heel_strike_mps2 {w.heel_strike_mps2[0]:.3g}"
        )
        for key in FIGURES:
            lines.append(f"  {key}: {m[key]:.4g} (the fitted walk: {m[key + '_fitted_walk']:.4g})")
    for key, why in cal.not_measured.items():
        lines.append(f"  not measured: {key} ({why})")
    print("\n".join(lines))
    return 0
