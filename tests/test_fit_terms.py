"""The finger table's term selection: it finds a residual's true terms by leave-one-design-out."""
import numpy as np

from softhand.studies.calibration.fit_terms import candidates, loo_rms, select_terms


def _rows(n_designs=12, seed=3):
    """Groups of n designs inside the calibrated box, three angles each."""
    rng = np.random.default_rng(seed)
    g = {"b_a": rng.uniform(0.5, 2.3, n_designs), "d_a": rng.uniform(1.7, 6.6, n_designs),
         "link_a": rng.uniform(3.4, 11.0, n_designs), "tie_link": rng.uniform(0.15, 0.75, n_designs)}
    theta = np.array([0.2, 0.6, 1.0])
    rows = {k: np.repeat(v, theta.size) for k, v in g.items()}
    rows["design"] = np.repeat(np.arange(n_designs), theta.size).astype(float)
    rows["theta"] = np.tile(theta, n_designs)
    return rows


def test_selection_finds_the_terms_a_residual_is_made_of():
    """y = 0.3 + 0.2 ln(b/a) - 0.1 (-ln(1 - w/L)) theta + 0.05 theta: the forward selection adds
    exactly ln(b/a) and the tie-theta product, and then predicts every left-out design to rounding."""
    rows = _rows()
    y = 0.3 + 0.2 * np.log(rows["b_a"]) - 0.1 * -np.log1p(-rows["tie_link"]) * rows["theta"] + 0.05 * rows["theta"]
    terms, rms, path = select_terms(rows, y)
    assert set(terms) == {"th", "lb", "lt*th"} and rms < 1e-10
    assert [p[0] for p in path] == list(terms) and path[0][1] > 0.01  # theta alone misses


def test_selection_stops_at_noise_and_loo_needs_enough_designs():
    """Pure noise: no design term lowers the leave-one-out error by 2 %, so theta stays alone;
    with as many coefficients as designs a fold is undetermined (inf)."""
    rows = _rows(n_designs=10, seed=5)
    noise = np.random.default_rng(1).normal(0.0, 0.01, rows["theta"].size)
    terms, _, _ = select_terms(rows, noise)
    assert terms == ("th",)
    pool = candidates(rows)
    assert {"lb", "ld", "lL", "lt", "lg", "s2", "th*th", "lb*th"} <= set(pool)
    assert loo_rms(rows, noise, ["th"] + pool[:9]) == np.inf
