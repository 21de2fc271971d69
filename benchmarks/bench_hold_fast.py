"""Speed of the fast hold model (reduced): one hold state, one holding limit, a 20 x 20 map.

Run: python benchmarks/bench_hold_fast.py   (targets: state <= 20 ms, limit <= 100 ms, map <= 30 s)

The paper's design, the calibrated finger, a 180 mm sphere of 0.5 kg (mu 0.5) at 1.2 MPa cavity
pressure; the state is the hand closed on it and the object let go (the weight's admissible
state); the holding limit adds the pull's linear program; the map is pump pressure 0.4-2.0 MPa x
mass 0.2-3 kg (each pressure's cavity pressure found and its closed hand reused across masses).
Best of 5 for the state and the limit (after one warm-up call: caches of the finger tables).
The sphere's limit falls as it slides (one evaluation of the slide beyond the grasp); the last
line is a holding limit with a long slide: a 150 mm ball at 1.8 MPa, held below its widest
section, wedging 36.5 mm into the fingers until it slips out.
"""
from __future__ import annotations

import time

import numpy as np

from softhand.reduced.holding import hold, hold_fast, hold_lp
from softhand.reduced.vocabulary.design import HandDesign
from softhand.reduced.holding.hand_layout import place_object
from softhand.reduced.holding.objects import GraspObject
from softhand.studies.hold import HoldMap, run_map


def best(fn, repeat: int = 5) -> tuple[float, float]:
    """(best wall time, best CPU time of this process) [s] of ``repeat`` calls: on a loaded
    machine the CPU time is the cost, the wall time what a user waits."""
    wall, cpu = [], []
    for _ in range(repeat):
        t, c = time.perf_counter(), time.process_time()
        fn()
        wall.append(time.perf_counter() - t)
        cpu.append(time.process_time() - c)
    return min(wall), min(cpu)


def main() -> None:
    d = hold_fast.finger_design(HandDesign())
    obj = GraspObject(diameter_mm=180.0, mass_kg=0.5, friction=0.5)
    placed = place_object(obj, d)
    hold.solve_hold(d, obj, P_cavity_MPa=1.2, placed=placed)
    weight = obj.mass_kg * d.g

    def state():
        closed = hold_fast.close_hand(1.2, placed, d)
        hold_lp.weight_state(hold.contact_set(closed, d), placed.centre, weight, obj.friction)

    t_state = best(state)
    t_limit = best(lambda: hold.solve_hold(d, obj, P_cavity_MPa=1.2, placed=placed))
    ball = GraspObject(diameter_mm=150.0, mass_kg=0.5, friction=0.8)
    wedge = hold.solve_hold(d, ball, P_cavity_MPa=1.8)
    t_wedge = best(lambda: hold.solve_hold(d, ball, P_cavity_MPa=1.8))
    m = HoldMap(HandDesign(), obj, ("pressure", tuple(np.linspace(0.4, 2.0, 20))),
                ("mass", tuple(np.linspace(0.2, 3.0, 20))))
    t, c = time.perf_counter(), time.process_time()
    rows = run_map(m)
    t_map, c_map = time.perf_counter() - t, time.process_time() - c
    print(f"one hold state (close + let go):     {1e3 * t_state[0]:7.1f} ms wall, {1e3 * t_state[1]:7.1f} ms CPU  (target 20 ms)")
    print(f"one holding limit (state + pull LP): {1e3 * t_limit[0]:7.1f} ms wall, {1e3 * t_limit[1]:7.1f} ms CPU  (target 100 ms)")
    print(f"20 x 20 map (pressure x mass):       {t_map:7.2f} s  wall, {c_map:7.2f} s  CPU  (target 30 s; "
          f"{sum(r['held'] for r in rows)} held)")
    print(f"one holding limit, a wedging ball:   {1e3 * t_wedge[0]:7.1f} ms wall, {1e3 * t_wedge[1]:7.1f} ms CPU  "
          f"({wedge.extra['slide_evaluations']} evaluations along {wedge.extra['slide_mm']:.1f} mm of slide)")


if __name__ == "__main__":
    main()
