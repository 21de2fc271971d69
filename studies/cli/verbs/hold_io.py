"""The ``softhand hold`` verb's inputs and outputs (:mod:`softhand.studies.cli.verbs.hold` runs it):
the options' limits, the object and the pull read from the command line, the progress bars,
and what ``--out`` receives, staged by the output rule.
"""
from __future__ import annotations

import sys
from contextlib import contextmanager
from pathlib import Path

from softhand.reduced.vocabulary.errors import InputError
from softhand.studies.cli.args import parse_values

#: named pull directions (hand frame: y down, x outward through finger 0, z = x cross y)
PULLS = {"down": (0, 1, 0), "up": (0, -1, 0), "x": (1, 0, 0), "-x": (-1, 0, 0), "z": (0, 0, 1), "-z": (0, 0, -1)}
#: option -> (lowest, highest)
LIMITS = {"--pressure-mpa": (-1.0, 5.0), "--cavity-pressure-mpa": (0.0, 5.0), "--mass-kg": (0.0, 100.0),
          "--friction": (0.0, 10.0), "--margin": (1.0, 100.0), "--pull-n": (0.0, 1e5), "--max-pump-mpa": (0.01, 5.0)}


def checked_option(args, option: str):
    """The number given for ``option`` (None: not given), InputError outside LIMITS."""
    value = getattr(args, option[2:].replace("-", "_"))
    if value is None:
        return None
    lo, hi = LIMITS[option]
    if not lo <= value <= hi:
        raise InputError(option, value, f"must be a number in [{lo:g}, {hi:g}]")
    return float(value)


def pull_direction(text: str):
    """The unit pull direction of ``--pull``: a name of PULLS or three numbers x,y,z."""
    from softhand.reduced.holding.hold import pull_unit

    if text in PULLS:
        return pull_unit(PULLS[text])
    values = parse_values(text, "--pull", 3, "x,y,z", more=None)
    if len(values) != 3:
        raise InputError("--pull", text, f"must be three numbers x,y,z or one of {', '.join(PULLS)}")
    return pull_unit(values, "--pull")


def object_from_args(args):
    """The object of ``--object``, with ``--mass-kg`` and ``--friction`` over its table's."""
    from dataclasses import replace

    from softhand.reduced.holding.objects import parse_object

    obj = parse_object(args.object)
    changes = {k: v for k, v in (("mass_kg", checked_option(args, "--mass-kg")),
                                 ("friction", checked_option(args, "--friction"))) if v is not None}
    return replace(obj, **changes) if changes else obj


def progress_bar(show: bool, desc: str):
    """(a tqdm bar on stderr, ``update(done, total)`` for the fast model's progress)."""
    from tqdm import tqdm

    bar = tqdm(desc=desc, unit="point", file=sys.stderr, leave=False, disable=not show)

    def update(done, total):
        bar.total = total
        bar.n = done
        bar.refresh()
    return bar, update


#: what ``hold --out DIR`` writes (its manifest: an earlier run's are replaced whole, nothing else)
OUTPUT_NAMES = ("result.json", "hold.pvd", "hold", "hold_map.csv", "hold_map.png")


@contextmanager
def staged(args):
    """The run's outputs staged and renamed into --out when whole (the project's output rule)."""
    from softhand.studies.io.files import UNWRITTEN, kept_if_unwritable
    from softhand.studies.io.outputs import replaced_outputs

    refused = len(UNWRITTEN)
    with replaced_outputs(args.out, OUTPUT_NAMES, verb="hold") as stage, \
            kept_if_unwritable(Path(args.out), "hold"):
        yield stage
    if len(UNWRITTEN) == refused:
        print(f"softhand hold: wrote {args.out}", file=sys.stderr)


def write_output(args, data: dict, name: str) -> None:
    """``data`` as the JSON file ``name`` in ``--out`` (staged), if ``--out`` is given."""
    if not args.out:
        return
    from softhand.studies.io.files import write_json

    with staged(args) as stage:
        write_json(stage / name, data)
