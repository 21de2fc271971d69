"""
A batch study from Python: the free hand's P(theta) for three finger moduli
===========================================================================

The same study a TOML file describes (``softhand study run studies/curve_moduli.toml``),
built from a dict: a kind, a design, sweep axes combined as a product. Results go to
``<results>/<name>/<case>/result.json`` plus ``index.csv``; a rerun reuses finished cases.
"""
import math
import tempfile

from softhand.reduced import hand, load_design
from softhand.studies import index_rows, run_study, study_from_dict

study = study_from_dict({
    "name": "moduli",
    "kind": "curve",
    "sweep": {"theta_deg": [15.0, 45.0, 75.0], "mu_sf_MPa": [1.0, 1.15, 1.3]},
})
results = tempfile.mkdtemp(prefix="softhand-example-")
first = run_study(study, results_root=results, workers=1, progress=False)
again = run_study(study, results_root=results, workers=1, progress=False)
print(f"{first.total} cases: {first.computed} computed; the rerun reused {again.reused}")
assert first.computed == 9 and again.reused == 9

rows = index_rows(study, results)
for row in rows:
    print(f"mu_sf = {row['mu_sf_MPa']:.2f} MPa, theta = {row['theta_deg']:4.0f} deg: "
          f"P = {row['P_pump_MPa']:.4f} MPa")

# Each case is the library call it stands for: eq. (27) on the swept design.
row = next(r for r in rows if r["mu_sf_MPa"] == 1.3 and r["theta_deg"] == 45.0)
direct = hand.pressure(math.radians(45.0), load_design().replace(mu_sf=1.3))
assert math.isclose(row["P_pump_MPa"], float(direct), rel_tol=1e-12)
