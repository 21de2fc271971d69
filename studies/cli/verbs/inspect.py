"""``softhand inspect``: render a VTK result coloured by a field; print its range and peak."""
from __future__ import annotations

import dataclasses

from softhand.studies.cli.args import add_json_option, print_json

HELP = "render a .vtm/.vtu/.pvd result (the deformed hand, object, forces) to PNG, GIF or MP4"


def configure(parser) -> None:
    parser.add_argument("file", metavar="FILE", help="a .vtm scene, a .vtu state or a .pvd series")
    parser.add_argument("--field", default=None,
                        help="field to colour by (default von_mises_MPa, else displacement_mm, "
                             "else height); NAME[i] for one component of a vector or tensor")
    parser.add_argument("--fields", action="store_true",
                        help="list the blocks and fields the file holds, draw nothing")
    parser.add_argument("--step", type=int, default=None,
                        help="step of a .pvd series (default: the last; negative from the end)")
    parser.add_argument("--view", default=None, help="camera: side (normal to the bending "
                        "plane; the default of a finger), iso (the default of a sheet), top, front")
    parser.add_argument("--one-finger", action="store_true",
                        help="draw only the modelled finger, not the hand's other fingers")
    parser.add_argument("--out", metavar="FILE.png", default=None,
                        help="picture to write (default: FILE_step<K>_<field>.png next to FILE)")
    parser.add_argument("--animate", metavar="OUT.gif|mp4", default=None,
                        help="render every step of a .pvd series into an animation instead")
    parser.add_argument("--interactive", action="store_true",
                        help="open a window (needs a display) instead of only writing the PNG")
    add_json_option(parser)


def run(args) -> int:
    from softhand.reduced.vocabulary.errors import InputError
    from softhand.studies.io.render import animate, describe, inspect

    if args.field is not None and not args.field.strip():
        raise InputError("--field", args.field, "must name a field (see --fields)")
    drawn = {"--out": args.out, "--animate": args.animate, "--interactive": args.interactive or None}
    if args.fields and (given := [k for k, v in drawn.items() if v is not None]):
        raise InputError("--fields", True, f"lists the fields and draws nothing; not with {given[0]}")
    if args.animate and (args.out is not None or args.step is not None):
        option = "--out" if args.out is not None else "--step"
        raise InputError(option, args.out if args.out is not None else args.step,
                         "not with --animate, which renders every step into its own file")
    if args.fields:
        rows = describe(args.file, args.step)
        if args.json:
            print_json(rows)
        for r in [] if args.json else rows:
            print(f"{r['block']:16s} {r['location']:5s} {r['field']:22s} {r['components']}")
        return 0
    if args.animate:
        summary = animate(args.file, args.animate, field=args.field, view=args.view,
                          hand=not args.one_finger)
    else:
        summary = inspect(args.file, field=args.field, step=args.step, out=args.out,
                          view=args.view, hand=not args.one_finger, interactive=args.interactive)
    if args.json:
        print_json(dataclasses.asdict(summary))
        return 0
    print(f"{summary.file}  step {summary.step} of 0..{summary.n_steps - 1}")
    line = f"{summary.field} ({summary.location} data): min {summary.minimum:.6g}  max {summary.maximum:.6g}"
    if not args.animate:
        x, y, z = summary.peak_at
        line += f"  peak at ({x:.4g}, {y:.4g}, {z:.4g}) mm"
    print(line)
    if summary.png:
        print(f"wrote {summary.png}")
    return 0
