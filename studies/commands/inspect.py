"""``softhand inspect``: render a VTK result coloured by a field; print its range and peak."""
from __future__ import annotations

import dataclasses

from studies.args import add_json_option, print_json

HELP = "render a .vtu/.pvd result (deformed, coloured by a field) to PNG; print its range"


def configure(parser) -> None:
    parser.add_argument("file", metavar="FILE", help="a .vtu state or a .pvd series")
    parser.add_argument("--field", default=None,
                        help="field to colour by (default von_mises, else displacement); "
                             "NAME[i] for one component of a vector or tensor")
    parser.add_argument("--step", type=int, default=None,
                        help="step of a .pvd series (default: the last; negative from the end)")
    parser.add_argument("--out", metavar="FILE.png", default=None,
                        help="picture to write (default: FILE_step<K>_<field>.png next to FILE)")
    parser.add_argument("--interactive", action="store_true",
                        help="open a window (needs a display) instead of only writing the PNG")
    add_json_option(parser)


def run(args) -> int:
    from studies.inspect import inspect

    summary = inspect(args.file, field=args.field, step=args.step, out=args.out,
                      interactive=args.interactive)
    if args.json:
        print_json(dataclasses.asdict(summary))
        return 0
    x, y, z = summary.peak_at
    print(f"{summary.file}  step {summary.step} of 0..{summary.n_steps - 1}")
    print(f"{summary.field} ({summary.location} data): min {summary.minimum:.6g}  "
          f"max {summary.maximum:.6g}  peak at ({x:.4g}, {y:.4g}, {z:.4g}) mm")
    if summary.png:
        print(f"wrote {summary.png}")
    return 0
