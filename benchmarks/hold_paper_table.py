"""The paper's two objects held by the whole-hand FEM: held or not, and the holding limit.

180 mm / 2 kg at 0.6 and 0.9 MPa, 240 mm / 6 kg at 1.1 and 1.4 MPa, each as a sphere and as an
upright cylinder (length = diameter), for mu = 0.3, 0.5, 0.8; pull straight down. One JSON line
per case is appended to ``--out`` as it finishes (a long run: start it with nice, in the
background; rerun skips the cases already there).

    nice python benchmarks/hold_paper_table.py [--mesh ci|default] [--out hold_paper_table.jsonl]
"""
from __future__ import annotations

import argparse
import json
import time
from dataclasses import replace
from pathlib import Path

from softhand.fem.hand.finger import FingerOptions
from softhand.fem.hand.hold import solve_hold
from softhand.fem.hand.hold_options import HoldOptions
from softhand.fem.newton import NotConverged
from softhand.reduced.vocabulary.design import HandDesign
from softhand.reduced.vocabulary.errors import InputError
from softhand.reduced.holding.objects import parse_object

CASES = [(D, m, P) for D, m, Ps in ((180, 2.0, (0.9, 0.6)), (240, 6.0, (1.4, 1.1))) for P in Ps]


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--mesh", default="ci", choices=("ci", "default"))
    parser.add_argument("--out", default="hold_paper_table.jsonl")
    parser.add_argument("--shapes", default="sphere,cylinder")
    parser.add_argument("--mu", default="0.8,0.5,0.3")
    parser.add_argument("--diameters", default="180,240")
    args = parser.parse_args()
    finger = FingerOptions() if args.mesh == "default" else FingerOptions(mesher="gmsh", mesh_size=10.0)
    out = Path(args.out)
    done = {json.loads(line)["case"] for line in out.read_text().splitlines()} if out.exists() else set()
    for D, m, P in CASES:
        if str(D) not in args.diameters.split(","):
            continue
        for shape in args.shapes.split(","):
            for mu in (float(x) for x in args.mu.split(",")):
                case = f"{shape}:{D} m={m} P={P} mu={mu} mesh={args.mesh}"
                if case in done:
                    continue
                text = f"sphere:{D}" if shape == "sphere" else f"cylinder:{D}x{D}"
                obj = replace(parse_object(text), mass_kg=m, friction=mu)
                t0 = time.perf_counter()
                try:
                    r = solve_hold(HandDesign(), obj, P_cavity_MPa=P, options=HoldOptions(finger=finger))
                    row = {"held": r.held, "holding_limit_N": r.holding_limit_N,
                           "holding_limit_kg": r.holding_limit_kg, "notes": list(r.notes),
                           "contacts": [(c.finger, c.link, round(c.normal_N, 3), round(c.friction_N, 3), c.state)
                                        for c in r.contacts]}
                except InputError as err:
                    row = {"refused": str(err)}
                except NotConverged as err:
                    row = {"failed": str(err).split("; residual history")[0]}
                row.update(case=case, wall_seconds=time.perf_counter() - t0)
                with out.open("a") as f:
                    f.write(json.dumps(row) + "\n")
                print(json.dumps(row), flush=True)


if __name__ == "__main__":
    main()
