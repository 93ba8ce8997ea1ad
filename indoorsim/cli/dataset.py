"""``indoorsim dataset`` and ``indoorsim train``: a labelled data set, and the network it trains.

``dataset`` writes fixed-length windows of many simulated walks as Parquet
shards (resumable, the same bytes whatever the number of workers);
``train`` fits the learned-io network on such a data set.
"""

from __future__ import annotations

import argparse
import sys
import textwrap
from pathlib import Path
from typing import TYPE_CHECKING

from indoorsim.cli.args import CliError, positive, seed_number

if TYPE_CHECKING:
    from indoorsim.cli.args import Subparsers

__all__ = ["add_dataset", "add_train"]


def add_dataset(subparsers: Subparsers) -> None:
    """Declare ``indoorsim dataset``."""
    parser = subparsers.add_parser(
        "dataset",
        help="generate a labelled data set of windows as Parquet shards (Dask)",
        description="Simulate many walks (bundled and generated sites, random routes, walkers, "
        "carrying modes with transitions, devices) and write fixed-length windows of the "
        "phone's streams with their truth labels as Parquet shards, plus a dataset card "
        "(dataset_card.json and README.md, with the schema). Runs on a local Dask cluster "
        "(--workers processes) or an existing one (--scheduler). The output is the same "
        "whatever the number of workers; an interrupted run resumes when the same command "
        "is run again. Options given here override the --config file's keys.",
    )
    parser.add_argument("--sites", type=positive(int), metavar="N", help="number of sites")
    parser.add_argument(
        "--walks-per-site", type=positive(int), metavar="K", help="walks in each site"
    )
    parser.add_argument(
        "--minutes", type=positive(float), metavar="M", help="length of each walk, minutes"
    )
    parser.add_argument("--seed", type=seed_number, metavar="S", help="seed of the data set (>= 0)")
    parser.add_argument(
        "--config",
        type=Path,
        metavar="FILE",
        help="YAML/JSON file with any key of the data-set configuration (see "
        "indoorsim.dataset.config.DatasetConfig)",
    )
    parser.add_argument(
        "--recordings",
        action="store_true",
        default=None,
        help="also save every walk's whole recording folder under recordings/",
    )
    where = parser.add_mutually_exclusive_group()
    where.add_argument(
        "--workers",
        type=positive(int),
        metavar="W",
        help="worker processes of the local cluster (default: the number of cores)",
    )
    where.add_argument(
        "--scheduler",
        metavar="ADDRESS",
        help="use an existing Dask cluster, e.g. tcp://10.0.0.5:8786 (its workers need "
        "indoorsim and --out at the same path)",
    )
    parser.add_argument(
        "--out", type=Path, required=True, metavar="DIR", help="the data set's folder"
    )
    parser.add_argument("--quiet", action="store_true", help="no progress bar")
    parser.set_defaults(handler=_run_dataset)


def _run_dataset(args: argparse.Namespace) -> int:
    from indoorsim.dataset import DatasetConfigError, load_config
    from indoorsim.dataset.driver import DatasetFolderError, ShardFailures, build_dataset

    overrides = {
        key: value
        for key, value in (
            ("sites", args.sites),
            ("walks_per_site", args.walks_per_site),
            ("minutes", args.minutes),
            ("seed", args.seed),
            ("recordings", args.recordings),
        )
        if value is not None
    }
    try:
        config = load_config(args.config, overrides)
    except DatasetConfigError as err:
        raise CliError(str(err)) from None
    try:
        report = build_dataset(
            config,
            args.out,
            workers=args.workers,
            scheduler=args.scheduler,
            progress=False if args.quiet else None,
            dask_logs=args.debug,
        )
    except DatasetFolderError as err:
        raise CliError(str(err)) from None
    except ShardFailures as err:
        print(f"indoorsim: {err}", file=sys.stderr)
        return 3
    text = (
        f"Wrote {args.out}: {report.shards} shards ({report.computed} computed now, "
        f"{report.skipped} already complete), {report.windows} windows, "
        f"{report.hours:.2f} hours of labelled data, in {report.wall_s:.1f} s. "
        f"Card: {args.out / 'dataset_card.json'} and {args.out / 'README.md'}."
    )
    print(textwrap.fill(text, width=88, break_on_hyphens=False))
    return 0


# --------------------------------------------------------------------- train


def add_train(subparsers: Subparsers) -> None:
    """Declare ``indoorsim train``."""
    parser = subparsers.add_parser(
        "train",
        help="train the learned-io inertial-odometry network on a data set",
        description="Train the small 1-D ResNet of the learned-io estimator (RoNIN-style "
        "velocity regression) on the train split of an `indoorsim dataset` folder, scoring "
        "the val split after each epoch and the test split at the end (an empty val or "
        "test split is warned about, an empty train split refused). Writes the checkpoint "
        "folder --out (weights.pt, tensors only, and model.json) atomically after every "
        "epoch; running the same "
        "command again resumes an interrupted run. Seeded and deterministic on CPU for a "
        "given --threads and --workers.",
    )
    parser.add_argument(
        "--data", type=Path, required=True, metavar="DIR", help="a finished data set folder"
    )
    parser.add_argument(
        "--out", type=Path, required=True, metavar="DIR", help="the checkpoint folder to write"
    )
    parser.add_argument("--epochs", type=positive(int), default=15, metavar="N")
    parser.add_argument("--batch-size", type=positive(int), default=128, metavar="B")
    parser.add_argument(
        "--lr", type=positive(float), default=3e-3, metavar="LR", help="Adam's initial step"
    )
    parser.add_argument("--seed", type=seed_number, default=0, metavar="S", help="seed (>= 0)")
    parser.add_argument(
        "--workers", type=seed_number, default=0, metavar="W", help="DataLoader workers (default 0)"
    )
    parser.add_argument(
        "--threads", type=positive(int), default=1, metavar="T", help="torch threads (default 1)"
    )
    # The frames of indoorsim.estimators.nn.inertial.FRAMES, spelled out so that
    # building the parser does not import torch.
    parser.add_argument(
        "--frame",
        choices=("world", "gravity_aligned"),
        default="world",
        help="input frame (default world)",
    )
    parser.add_argument(
        "--members",
        type=positive(int),
        default=1,
        metavar="N",
        help="train an ensemble of N networks, seeds S to S+N-1, into --out/member-K and "
        "name them in --out/ensemble.json; learned-io averages their velocities (default 1)",
    )
    parser.add_argument(
        "--overwrite", action="store_true", help="replace a checkpoint of another run at --out"
    )
    parser.add_argument("--quiet", action="store_true", help="no progress bar or epoch lines")
    parser.set_defaults(handler=_run_train)


def _run_train(args: argparse.Namespace) -> int:
    from indoorsim.dataset.train import (
        TrainConfig,
        TrainingFolderError,
        describe,
        train,
        train_ensemble,
    )

    try:
        config = TrainConfig(
            epochs=args.epochs,
            batch_size=args.batch_size,
            lr=args.lr,
            seed=args.seed,
            frame=args.frame,
            workers=args.workers,
            threads=args.threads,
        )
    except ValueError as err:
        raise CliError(str(err)) from None
    if not args.data.is_dir():
        raise CliError(f"--data {args.data}: not a folder")
    command = " ".join(
        [
            "indoorsim train",
            f"--data {args.data} --out {args.out}",
            f"--epochs {args.epochs} --batch-size {args.batch_size} --lr {args.lr:g}",
            f"--seed {args.seed} --workers {args.workers} --threads {args.threads}",
            f"--frame {args.frame}",
            *([f"--members {args.members}"] if args.members > 1 else []),
        ]
    )
    how = {
        "overwrite": args.overwrite,
        "progress": False if args.quiet else None,
        "log": None if args.quiet else lambda line: print(line, file=sys.stderr),
        "command": command,
        # Even with --quiet: a run without a validation or test loss is worth a line.
        "warn": lambda line: print(f"indoorsim: warning: {line}", file=sys.stderr),
    }
    try:
        if args.members > 1:
            reports = train_ensemble(args.data, args.out, config, members=args.members, **how)
        else:
            reports = [train(args.data, args.out, config, **how)]
    except TrainingFolderError as err:
        raise CliError(str(err)) from None
    for report in reports:
        print(textwrap.fill(describe(report), width=88, break_on_hyphens=False))
    if args.members > 1:
        print(f"{args.out}: an ensemble of {args.members} members (ensemble.json).")
    return 0
