"""The fast hold model beside whole-hand FEM holds: the same object, mass, friction, pull and cavity pressure.

Give it the JSON that ``softhand hold --model fem --json`` printed (one file per case, or
``result.json`` from its ``--out`` directory); for each it runs the fast model (``--model
reduced``, calibrated finger) on the case the FEM ran and prints one row: held or not, the
holding limit and one pad's normal force in each, and the relative differences. The FEM's rows
take minutes each (make them first, e.g. with nice in the background); this takes a second.
``--reference`` runs the fast model on the FEM holds the project keeps instead
(``studies/data/hold_fem_limits.json``, :mod:`softhand.studies.hold_reference`: 61 cases, ~20 s)
and prints each verdict and error and how many limits (and loads borne, weight + limit) are
within 5 and 10 %.

    python benchmarks/hold_fast_vs_fem.py RESULT.json [RESULT.json ...] [--markdown]
    python benchmarks/hold_fast_vs_fem.py --reference [--markdown]
"""
from __future__ import annotations

import argparse
import json
import math
from pathlib import Path

from softhand.reduced.holding.hold import solve_hold
from softhand.reduced.holding.objects import object_from_table
from softhand.reduced.vocabulary.design import HandDesign


def describe(obj: dict) -> str:
    """The object in a few words: shape and size, and its rotation and offset where it has them."""
    shape = obj["shape"]
    if shape == "sphere":
        text = f"sphere {obj['diameter_mm']:g} mm"
    elif shape == "box":
        text = "box " + " x ".join(f"{v:g}" for v in obj["size_mm"]) + " mm"
    elif shape in ("cylinder", "capsule"):
        text = f"{shape} {obj['diameter_mm']:g} x {obj['length_mm']:g} mm"
    else:
        text = f"mesh {Path(obj.get('file') or '').name}"
    for key, unit in (("rotation_deg", "°"), ("offset_mm", " mm")):
        if any(obj.get(key) or ()):
            text += f", {key.split('_')[0]} (" + ", ".join(f"{v:g}" for v in obj[key]) + f"){unit}"
    return text


def pad_N(result: dict) -> float:
    """The largest normal force on one pad in the state reported [N]."""
    return max((c["normal_N"] for c in result["contacts"]), default=0.0)


def row(fem: dict) -> dict:
    table = {k: v for k, v in fem["object"].items() if v is not None}
    obj = object_from_table(table, source="FEM result")
    fast = solve_hold(HandDesign(), obj, P_cavity_MPa=fem["P_cavity_MPa"], pull_direction=fem["pull_direction"]).to_json()
    return {"object": describe(fem["object"]), "mass_kg": fem["mass_kg"], "friction": fem["friction"],
            "P_cavity_MPa": fem["P_cavity_MPa"], "fem_held": fem["held"], "fem_limit_N": fem["holding_limit_N"],
            "fem_pad_N": pad_N(fem), "fast_held": fast["held"], "fast_limit_N": fast["holding_limit_N"],
            "fast_pad_N": pad_N(fast)}


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("results", nargs="*", help="FEM hold JSON files (softhand hold --model fem --json)")
    parser.add_argument("--reference", action="store_true",
                        help="the FEM holds kept in studies/data/hold_fem_limits.json instead")
    parser.add_argument("--markdown", action="store_true", help="print a Markdown table")
    args = parser.parse_args()
    if args.reference == bool(args.results):
        parser.error("give FEM result files or --reference")
    if args.reference:
        reference(args.markdown)
        return
    rows = [row(json.loads(open(path, encoding="utf-8").read())) for path in args.results]
    pct = lambda a, b: f"{100.0 * (a / b - 1.0):+.1f} %" if b else "—"  # noqa: E731
    head = ["object", "mass kg", "mu", "P_cavity MPa", "FEM held, limit N", "fast held, limit N", "limit",
            "FEM N/pad", "fast N/pad", "N"]
    if args.markdown:
        print("| " + " | ".join(head) + " |")
        print("|" + "---|" * len(head))
    for r in rows:
        cells = [r["object"], f"{r['mass_kg']:g}", f"{r['friction']:g}", f"{r['P_cavity_MPa']:g}",
                 f"{'yes' if r['fem_held'] else 'no'}, {r['fem_limit_N']:.2f}",
                 f"{'yes' if r['fast_held'] else 'no'}, {r['fast_limit_N']:.2f}",
                 pct(r["fast_limit_N"], r["fem_limit_N"]) if r["fem_held"] and r["fast_held"] else "",
                 f"{r['fem_pad_N']:.2f}", f"{r['fast_pad_N']:.2f}", pct(r["fast_pad_N"], r["fem_pad_N"])]
        print("| " + " | ".join(cells) + " |" if args.markdown else "  ".join(cells))


def reference(markdown: bool) -> None:
    """The fast model on the kept FEM holds: one row each, then the summary."""
    from softhand.studies import hold_reference

    rows = hold_reference.compare()
    sep = " | " if markdown else "  "
    if markdown:
        print("| case | P_cavity MPa | FEM limit N | fast limit N | fast / FEM - 1 | load borne: fast / FEM - 1 |\n"
              "|---|---|---|---|---|---|")
    for r in rows:
        cells = [r.name, f"{r.P_cavity_MPa:.3f}",
                 f"{r.fem_limit_N:.2f}" if r.fem_held else f"not held ({100 * (1 + r.fem_margin):.0f} % of the weight)",
                 f"{r.fast_limit_N:.2f}" if r.fast_held else "not held",
                 f"{100 * r.error:+.1f} %" if math.isfinite(r.error) else "",
                 f"{100 * r.load_error:+.1f} %" if r.fem_held and r.fast_held else ""]
        print(("| " if markdown else "") + sep.join(cells) + (" |" if markdown else ""))
    s = hold_reference.summary(rows)
    print(f"# {s['cases']} FEM holds: verdicts agree on {s['verdicts_agree']}"
          + "".join(f" (differ: {name}, the FEM's margin {100 * m:+.1f} %)" for name, m in s["differ"])
          + f"; of the {s['both_held']} both hold, the fast limit within 5 % on {s['within_5_percent']}, within "
          f"10 % on {s['within_10_percent']}; rms {s['rms_percent']:.1f} %, median {s['median_percent']:.1f} %; the load "
          f"borne (weight + limit) within 5 % on {s['load_within_5_percent']}, within 10 % on {s['load_within_10_percent']}, "
          f"median {s['load_median_percent']:.1f} %")


if __name__ == "__main__":
    main()
