"""The one-sided pads' bounds (tactsense.analysis.pad_censored), each against an
independent evaluation: the censored Fisher weight against a quadrature of the censored
likelihood's score, the censored bound against a Monte-Carlo of the maximum-likelihood
estimator, the Bayesian average against a direct midpoint-rule integration and the
Bayesian bound against the mean square error of the posterior mean, computed by direct
numerical integration over a grid of positions."""

import math

import numpy as np
import pytest
from scipy import integrate, optimize, special, stats

from tactsense.analysis import pad_censored as pc
from tactsense.physics.contact import grams_force
from tactsense.physics.indenters import SphereProbe
from tactsense.physics.pad_response import pad_strain
from tactsense.sensor.registry import preset

F50 = grams_force(50)


@pytest.mark.parametrize("alpha", [-4.0, -1.0, 0.0, 0.7, 2.0, 4.0])
def test_censored_weight_matches_quadrature_of_the_likelihood(alpha):
    # y = max(mu + n, c), sigma = 1, mu = 0, c = alpha: the score by numerical
    # differentiation of the log-likelihood, its square integrated (quad) over the
    # uncensored readings plus the point mass at c; none of pc's arithmetic
    h = 1e-5

    def log_density(y, mu):
        return stats.norm.logpdf(y - mu)

    def log_mass(mu):
        return stats.norm.logcdf(alpha - mu)

    def score_sq_density(y):
        s = (log_density(y, h) - log_density(y, -h)) / (2 * h)
        return s**2 * math.exp(log_density(y, 0.0))

    uncensored, _ = integrate.quad(score_sq_density, alpha, np.inf, epsabs=1e-13)
    s_mass = (log_mass(h) - log_mass(-h)) / (2 * h)
    expected = uncensored + s_mass**2 * math.exp(log_mass(0.0))
    # 1e-6 relative: the central difference's h^2 error and quad's tolerance
    assert float(pc.censored_weight(alpha)) == pytest.approx(expected, rel=1e-6, abs=1e-12)


def test_censored_weight_limits():
    # the unclipped Gaussian far above rest, 1/2 + 2 phi(0)^2 at rest, none far below
    w = pc.censored_weight([-30.0, 0.0, 30.0])
    assert w[0] == pytest.approx(1.0, abs=1e-12)
    assert w[1] == pytest.approx(0.5 + 1.0 / math.pi, rel=1e-12)
    assert w[2] < 1e-150


def test_neighbours_of_a_centred_probe_are_in_tension_206_counts():
    # docs/sensors.md: with 50 g centred on a pad16 taxel the four neighbours' strain is
    # about -206 counts' worth (counts_per_strain x strain), thrown away by the clip
    spec = preset("pad16")
    g = spec.grid
    strain = pad_strain(spec, [SphereProbe(8 * g.row_pitch_mm, 8 * g.col_pitch_mm, F50, 1.6)])
    latent = pc.latent_counts(spec, strain) - spec.electronics.nominal_counts
    neighbours = [latent[7, 8], latent[9, 8], latent[8, 7], latent[8, 9]]
    assert np.allclose(neighbours, -206.0, atol=0.5)
    assert np.sum(latent > 0) == 1  # the centre taxel is the only one compressed


def test_rank_test_reports_the_centred_probe_singular_and_the_censored_bound_finite():
    spec = preset("pad16")
    x = y = 8 * 2.5
    classic = pc.point_bound(spec, x, y, F50, model="classic")
    assert classic["singular"] and math.isinf(classic["position_mm"])
    assert classic["smallest_ratio"] < pc.RANK_TOLERANCE
    censored = pc.point_bound(spec, x, y, F50, model="censored", noise_counts=41.0)
    unclipped = pc.point_bound(spec, x, y, F50, model="unclipped", noise_counts=41.0)
    assert not censored["singular"] and censored["smallest_ratio"] > 1e-3
    # censoring keeps less than a two-sided transducer's information, more than none
    assert unclipped["x_mm"] < censored["x_mm"] < math.inf
    quarter = pc.point_bound(spec, x + 0.625, y + 0.625, F50, model="classic")
    assert not quarter["singular"] and quarter["smallest_ratio"] > 0.1


def test_pad12x32_centred_classic_bound_is_singular_not_numerical():
    # the finite value printed there before came from a condition number of 8e12 under
    # an absolute cut-off; the scaled rank test calls it singular
    spec = preset("pad12x32")
    b = pc.point_bound(spec, 6 * 2.0, 16 * 2.0, F50, model="classic")
    assert b["singular"]


def test_capacitive_pad_is_two_sided_all_models_agree():
    spec = preset("pad4")
    bounds = [pc.point_bound(spec, 6.0, 6.0, F50, model=m) for m in pc.MODELS]
    assert bounds[0]["x_mm"] == bounds[1]["x_mm"] == bounds[2]["x_mm"]


def _tobit_fit(y, mu0, a_unwhitened, sigma, rest, start):
    """Maximum likelihood of the linear Tobit model y = max(mu0 + G d + n, rest)."""

    def nll(d):
        mu = mu0 + a_unwhitened @ d
        z = (y - mu) / sigma
        alpha = (rest - mu) / sigma
        censored = y <= rest
        value = np.where(censored, -special.log_ndtr(alpha), 0.5 * z**2)
        ratio = np.exp(stats.norm.logpdf(alpha) - special.log_ndtr(alpha))
        dmu = np.where(censored, ratio / sigma, -z / sigma)
        return value.sum(), a_unwhitened.T @ dmu

    options = {"ftol": 1e-14, "gtol": 1e-9, "maxiter": 500}
    result = optimize.minimize(nll, start, jac=True, method="L-BFGS-B", options=options)
    return result.x, result.success


def _linearized(spec, theta, sigma_read):
    """The noise, rest reading, latent mean at ``theta`` and its unwhitened Jacobian."""
    sigma = math.sqrt(pc.noise_variance(spec, sigma_read))
    rest, _, _ = pc.rest_and_slope(spec)
    mu0 = pc._latent(spec, theta, 1.6)
    a = pc.whitened_jacobian(spec, *theta, model="unclipped", noise_counts=sigma_read)
    return sigma, rest, mu0, a * sigma  # w = 1 for the unclipped model: a sigma = G


def test_censored_bound_matches_monte_carlo_of_the_maximum_likelihood_estimator():
    # pad16, 50 g midway between two taxels along x, read noise 20 counts: the classic
    # bound is singular there (y moves no compressed taxel) and the unclipped one puts y
    # 6x tighter than the censored. High SNR: 25 frames of the same contact, the
    # readings' mean linearized at the truth (its Jacobian by central differences of
    # the layer model), frames y = max(mean + noise, rest), each set fitted by maximum
    # likelihood of the censored model (scipy L-BFGS-B from a random start). 300 fits:
    # the sample standard deviation's own error is ~4 %; 15 % tolerance.
    spec = preset("pad16")
    theta = np.array([8.5 * 2.5, 8 * 2.5, F50])
    sigma, rest, mu0, g = _linearized(spec, theta, 20.0)
    frames = 25
    bound = pc.point_bound(spec, *theta, model="censored", noise_counts=20.0)
    unclipped = pc.point_bound(spec, *theta, model="unclipped", noise_counts=20.0)
    assert pc.point_bound(spec, *theta, model="classic", noise_counts=20.0)["singular"]
    scale = np.array([bound["x_mm"], bound["y_mm"], bound["force_n"]]) / math.sqrt(frames)
    mu, gg = np.tile(mu0, frames), np.tile(g * scale, (frames, 1))
    rng = np.random.default_rng(3)
    fits = []
    for _ in range(300):
        y = np.maximum(mu + sigma * rng.standard_normal(mu.size), rest)
        d, success = _tobit_fit(y, mu, gg, sigma, rest, rng.standard_normal(3))
        if success:
            fits.append(d)
    assert len(fits) >= 290
    spread = np.std(np.array(fits), axis=0, ddof=1)  # in units of the censored bound
    assert np.allclose(spread, 1.0, atol=0.15), spread
    assert spread[1] * bound["y_mm"] > 3 * unclipped["y_mm"]  # the unclipped one is wrong


def test_censored_fisher_matrix_matches_the_score_covariance():
    # E[score score^T] = J: the score of the censored likelihood (its own formula, not
    # the weight w) at the truth, averaged over 4000 frames; pad16 a tenth of a pitch
    # off a taxel, 50 counts: within 8 % (the Monte-Carlo error is ~2-3 %)
    spec = preset("pad16")
    theta = np.array([8.1 * 2.5, 8 * 2.5, F50])
    sigma, rest, mu0, g = _linearized(spec, theta, 50.0)
    a = pc.whitened_jacobian(spec, *theta, model="censored", noise_counts=50.0)
    rng = np.random.default_rng(1)
    y = np.maximum(mu0 + sigma * rng.standard_normal((4000, mu0.size)), rest)
    alpha = (rest - mu0) / sigma
    ratio = np.exp(stats.norm.logpdf(alpha) - special.log_ndtr(alpha))
    dmu = np.where(y <= rest, -ratio / sigma, (y - mu0) / sigma**2)
    scores = dmu @ g
    assert np.allclose(np.diag(scores.T @ scores) / 4000, np.diag(a.T @ a), rtol=0.08)


def test_bayesian_average_matches_a_direct_midpoint_integration():
    # the Gauss-Legendre prior mean of J against a 20 x 20 midpoint rule with the cos^2
    # density written out: within 8 %. The layer model's grid makes J rough at a few
    # per cent across the cell: Gauss-Legendre with 8, 12, 16, 24, 32 nodes gave J_xx
    # 795, 855, 799, 836, 850 and J_FF 8434-9022 (pad16, 41 counts), so neither rule
    # converges below ~5 %; the bound (J^-1/2) carries half that
    spec = preset("pad16")
    noise = 41.0
    gauss = pc.bayesian_information(spec, F50, noise_counts=noise)
    n, pitch = 20, 2.5
    s = (np.arange(n) + 0.5) / n - 0.5  # in pitches
    density = 2 * np.cos(np.pi * s) ** 2 / n  # (2/L) cos^2(pi s / L) ds, ds = L / n
    direct = np.zeros((3, 3))
    for i, si in enumerate(s):
        for j, sj in enumerate(s):
            a = pc.whitened_jacobian(
                spec, (8 + si) * pitch, (8 + sj) * pitch, F50, noise_counts=noise
            )
            direct += density[i] * density[j] * (a.T @ a)
    assert np.allclose(np.diag(gauss), np.diag(direct), rtol=0.08)


def test_bayesian_bound_lies_under_the_posterior_mean_error():
    # one dimension: x random over a pad16 cell (cos^2 prior), y and the force known,
    # censored frames at 41 counts (1 % of full scale). The mean square error of the
    # posterior mean (posterior on a 161-point grid of x, by direct numerical
    # integration of the censored likelihood) over 1500 draws must be at least the Van
    # Trees bound 1 / (E[J_xx] + J_p). Measured: 0.0234 mm^2 against 0.00108: the bound
    # is 21x loose here (J_xx varies 2000-fold across the cell, near nil at the taxel's
    # centre, and Van Trees averages information, not its inverse), and the MSE lies
    # below the cell's mean point bound E[1 / J_xx] (0.085 mm^2; the posterior mean
    # leans on the prior where the frame says little).
    spec = preset("pad16")
    noise = 41.0
    sigma = math.sqrt(pc.noise_variance(spec, noise))
    rest, _, _ = pc.rest_and_slope(spec)
    grid = np.linspace(-1.25, 1.25, 161)
    mus = np.array([pc._latent(spec, (20.0 + u, 20.0, F50), 1.6) for u in grid])
    prior = np.cos(np.pi * grid / 2.5) ** 2
    prior /= prior.sum()
    rng = np.random.default_rng(5)
    errors = []
    for _ in range(1500):
        k = rng.choice(grid.size, p=prior)
        y = np.maximum(mus[k] + sigma * rng.standard_normal(mus.shape[1]), rest)
        censored = y <= rest
        loglik = np.where(
            censored,
            special.log_ndtr((rest - mus) / sigma),
            -0.5 * ((y - mus) / sigma) ** 2,
        ).sum(axis=1)
        post = prior * np.exp(loglik - loglik.max())
        errors.append(np.sum(post * grid) / post.sum() - grid[k])
    mse = float(np.mean(np.square(errors)))
    u, w = np.polynomial.legendre.leggauss(16)
    w = w * np.cos(0.5 * np.pi * u) ** 2
    w /= w.sum()
    jxx = sum(
        wi
        * pc.whitened_jacobian(spec, 20.0 + 1.25 * ui, 20.0, F50, noise_counts=noise)[:, 0]
        @ pc.whitened_jacobian(spec, 20.0 + 1.25 * ui, 20.0, F50, noise_counts=noise)[:, 0]
        for ui, wi in zip(u, w, strict=True)
    )
    bound = 1.0 / (jxx + pc.cell_prior_information(2.5))
    # the MSE's Monte-Carlo error is ~4 % at 1500 draws: 0.9 leaves room for it
    assert mse >= 0.9 * bound
    j_grid = np.array(
        [
            (lambda a: a[:, 0] @ a[:, 0])(
                pc.whitened_jacobian(spec, 20.0 + v, 20.0, F50, noise_counts=noise)
            )
            for v in grid[::4]
        ]
    )
    mean_point_bound = float(np.sum(prior[::4] / j_grid) / np.sum(prior[::4]))
    assert 15 * bound < mse < mean_point_bound  # docs/accuracy.md: "21 times" above the bound


def test_noise_from_full_scale_and_bad_values():
    spec = preset("pad16")
    assert pc.noise_from_full_scale(spec, 1.0) == pytest.approx(40.95)
    for bad in (0.0, -1.0, 51.0, math.nan):
        with pytest.raises(pc.TactsenseInputError):
            pc.noise_from_full_scale(spec, bad)
    with pytest.raises(pc.TactsenseInputError):
        pc.point_bound(spec, 20.0, 20.0, F50, model="bogus")


def test_design_bound_on_a_centred_probe_reports_singular_and_the_other_bounds():
    import json

    from typer.testing import CliRunner

    from tactsense.cli import app

    result = CliRunner().invoke(
        app,
        ["design", "bound", "--sensor", "pad16", "--x-mm", "20", "--y-mm", "20",
         "--noise-fs", "2", "--json"],
    )  # fmt: skip
    assert result.exit_code == 0, result.output
    data = json.loads(result.output)
    assert data["bound"] is None  # the classic bound: singular
    rows = {(r["noise"], r["bound"]): r for r in data["bounds"]}
    assert rows[("preset", "classic")]["singular"] is True
    assert rows[("preset", "classic")]["x_mm"] is None  # strict JSON: null, not Infinity
    assert "Infinity" not in result.output
    assert rows[("2 % FS", "censored")]["noise_counts"] == pytest.approx(81.9)
    assert math.isfinite(rows[("2 % FS", "censored")]["x_mm"])
    assert rows[("2 % FS", "bayesian")]["x_mm"] < rows[("2 % FS", "censored")]["x_mm"]
