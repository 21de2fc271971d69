"""``softhand material fit``: fit a rubber model to nominal stress vs stretch test data.

    softhand material fit --data studies/data/treloar1944.csv --model yeoh \\
        [--stability-range 0.2:5] [--json] [--plot FILE.png] [--out FILE.toml]

Data: CSV with columns ``mode,stretch,stress_MPa`` (mode: uniaxial, equibiaxial or
pure-shear, any mix; nominal stress). Prints the parameters with standard errors, their
correlations, the rms error per mode, the initial shear modulus and the Drucker stability
over the stated stretch range (a warning on stderr if unstable). ``--out`` writes
``[finger.material]`` and ``[reservoir.material]`` tables: a design file every verb reads
with ``--design`` (copy the table you need into your own design file).
"""
from __future__ import annotations

import sys

import numpy as np

from softhand.reduced.vocabulary.design_rules import BOUNDS
from softhand.reduced.vocabulary.errors import InputError
from softhand.reduced.vocabulary.inputfiles import plain_float
from softhand.studies.cli.args import add_json_option, print_json, print_table

HELP = "rubber models: fit Mooney-Rivlin, Yeoh, Gent, Ogden, Neo-Hookean to test data"


def configure(parser) -> None:
    sub = parser.add_subparsers(dest="action", required=True, metavar="fit")
    fit = sub.add_parser("fit", help="least-squares fit to nominal stress vs stretch data",
                         description="least-squares fit of a rubber model to test data")
    fit.add_argument("--data", required=True, metavar="FILE.csv",
                     help="columns mode,stretch,stress_MPa (mode: uniaxial | equibiaxial | "
                          "pure-shear); '#' comments")
    from softhand.reduced.materials.material_fit import FIT_MODELS

    fit.add_argument("--model", required=True, metavar="|".join(FIT_MODELS),
                     help="the strain energy to fit")
    fit.add_argument("--stability-range", default=None, metavar="LO:HI",
                     help="stretches of the Drucker check in every mode, within 0.01:100 "
                          "(default: 1/max .. max stretch of the data)")
    add_json_option(fit)
    fit.add_argument("--plot", metavar="FILE.png", help="data and fitted curves per mode")
    fit.add_argument("--out", metavar="FILE.toml",
                     help="write [finger.material] and [reservoir.material] tables")


def run(args) -> int:
    from softhand.reduced.materials.material_fit import fit_material
    from softhand.reduced.materials.stress_data import read_test_data
    from softhand.reduced.materials.rubber import drucker_check

    data = read_test_data(args.data)
    stretch_range = _stretch_range(args.stability_range, data)
    result = fit_material(data, args.model)
    lo, hi = BOUNDS["mu_sf_MPa"]
    if not lo <= result.material.mu0 <= hi:  # e.g. stresses in kPa under a stress_MPa header
        raise InputError("--data", args.data, f"fits an initial shear modulus of {result.material.mu0:.4g} MPa, "
                         f"outside the [{lo:g}, {hi:g}] MPa a design takes (a rubber's is about 0.1-10 MPa): "
                         "are the stresses in MPa?")
    drucker = drucker_check(result.material, stretch_range)
    notes = list(result.warnings)
    if not drucker["stable"]:
        u = drucker["first_unstable"]
        notes.append(f"the fit is not Drucker-stable in {u['mode']} at stretch {u['stretch']:.4g} "
                     f"(checked {stretch_range[0]:.4g}..{stretch_range[1]:.4g}); do not use it there")
    from softhand.studies.io.files import kept_if_unwritable, write_atomic

    if args.out:
        with kept_if_unwritable(args.out, "material fit"):
            write_atomic(args.out, material_toml(result, args.data))
    if args.plot:
        with kept_if_unwritable(args.plot, "material fit"):
            plot_material_fit(args.plot, result)
    for note in notes:
        print(f"softhand material fit: warning: {note}", file=sys.stderr)
    if args.json:
        print_json(_report(result, drucker, args, notes))
    else:
        _print_report(result, drucker)
    return 0


def _stretch_range(text, data) -> tuple[float, float]:
    """``--stability-range`` LO:HI within the stretches of rubber tests (default: the data's)."""
    from softhand.reduced.materials.stress_data import STRETCH_LIMITS

    if text is None:
        top = float(np.max(np.maximum(data.stretch, 1.0 / data.stretch)))
        return 1.0 / top, top
    try:
        lo, hi = (plain_float(x) for x in text.split(":"))
    except ValueError:
        lo = hi = float("nan")
    low, high = STRETCH_LIMITS
    if not low <= lo < hi <= high:
        raise InputError("--stability-range", text, f"must be LO:HI with {low:g} <= LO < HI <= "
                         f"{high:g} (the stretches of rubber tests)")
    return lo, hi


def _report(result, drucker, args, notes) -> dict:
    names = list(result.names)
    num = lambda x: float(x) if np.isfinite(x) else None  # noqa: E731
    return {
        "model": args.model, "material_model": result.material.model, "data": args.data,
        "parameters": dict(zip(names, map(float, result.values))),
        "std_errors": {k: num(v) for k, v in zip(names, result.stderr)},
        "correlation": {"names": names, "matrix": [[num(c) for c in row] for row in result.correlation]},
        "rms_error_by_mode": result.rms_by_mode(), "rms_error_MPa": result.rms,
        "n_points": len(result.data), "n_points_by_mode": _counts(result.data),
        "mu0_MPa": result.material.mu0, "drucker": drucker, "warnings": notes,
    }


def _counts(data) -> dict:
    modes, counts = np.unique(data.mode, return_counts=True)
    return {str(m): int(c) for m, c in zip(modes, counts)}


def _print_report(result, drucker) -> None:
    rows = [{"parameter": k, "value": float(v), "std_error": float(s)}
            for k, v, s in zip(result.names, result.values, result.stderr)]
    print(f"{result.fit_model} fitted to {len(result.data)} points of {result.data.source}")
    print_table(rows, digits=6)
    if len(result.names) > 1:
        print("correlation:")
        print_table([{"": k, **{n: float(c) for n, c in zip(result.names, row)}}
                     for k, row in zip(result.names, result.correlation)], digits=3)
    print("rms error [MPa]: " + ", ".join(f"{m} {v:.4g}" for m, v in result.rms_by_mode().items())
          + f"; all {result.rms:.4g}")
    print(f"initial shear modulus mu0 = {result.material.mu0:.6g} MPa")
    lo, hi = drucker["range"]
    verdict = "stable" if drucker["stable"] else "NOT stable"
    print(f"Drucker stability over stretches {lo:.4g}..{hi:.4g} (uniaxial, equibiaxial, pure shear): "
          f"{verdict}" + (f" ({drucker['skipped']} points beyond locking skipped)" if drucker["skipped"] else ""))


def material_toml(result, source) -> str:
    """``[finger.material]`` and ``[reservoir.material]`` tables of the fitted model."""
    m = result.material
    body = [f'model = "{m.model}"'] + [f"{k} = {v!r}" for k, v in m.parameters().items()]
    rms = ", ".join(f"{k} {v:.4g}" for k, v in result.rms_by_mode().items())
    head = [f"# {result.fit_model} fitted by 'softhand material fit' to {source}",
            f"# ({len(result.data)} points; rms error [MPa]: {rms}); initial shear modulus "
            f"{m.mu0:.6g} MPa.", "# A design file (other keys: the paper's); copy the table "
            "you need into your own design file."]
    return "\n".join(head + ["", "[finger.material]", *body, "", "[reservoir.material]", *body]) + "\n"


def plot_material_fit(path, result) -> None:
    """Data (markers) and the fitted model (lines), nominal stress vs stretch per mode."""
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    from softhand.studies.io.files import save_figure

    fig, ax = plt.subplots(figsize=(6, 4.5))
    data = result.data
    for k, mode in enumerate(result.rms_by_mode()):
        rows = data.mode == mode
        lam = np.linspace(min(1.0, data.stretch[rows].min()), max(1.0, data.stretch[rows].max()), 200)
        ax.plot(data.stretch[rows], data.stress[rows], "o", ms=4, color=f"C{k}", label=f"{mode} data")
        ax.plot(lam, result.material.nominal_stress(mode, lam), "-", color=f"C{k}",
                label=f"{mode} fit (rms {result.rms_by_mode()[mode]:.3g} MPa)")
    ax.set(xlabel="stretch [-]", ylabel="nominal stress [MPa]",
           title=f"{result.fit_model} fitted to {data.source}")
    ax.grid(alpha=0.3)
    ax.legend(fontsize=8)
    save_figure(fig, path)
