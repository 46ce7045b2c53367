import numpy as np
import pytest

from drake_biped.analysis.return_map import complex_list, fit_return_map, section_pairs, step_jacobian

P = np.array([[1.0, 0.4], [-0.3, 2.0]])  # a non-orthogonal basis: A is not symmetric


def real_map(l1, l2):
    return P @ np.diag([l1, l2]) @ np.linalg.inv(P)


def complex_map(re, im):
    return P @ np.array([[re, -im], [im, re]]) @ np.linalg.inv(P)


def simulate(a, x_star, starts, steps, noise, rng):
    seqs = []
    for x0 in starts:
        x = np.empty((steps, 2))
        x[0] = x0
        for n in range(1, steps):
            x[n] = x_star + a @ (x[n - 1] - x_star) + noise * rng.standard_normal(2)
        seqs.append(x)
    return seqs


X_STAR = np.array([0.5, -1.2])


def sorted_eigs(e):
    return np.array(sorted(np.asarray(e, dtype=complex), key=lambda z: (round(z.real, 9), z.imag)))


@pytest.mark.parametrize("a, expected", [
    (real_map(0.318, -0.234), [-0.234, 0.318]),
    (complex_map(0.064, 0.101), [0.064 - 0.101j, 0.064 + 0.101j]),
])
def test_noise_free_fit_recovers_the_chosen_eigenvalues_exactly(a, expected):
    rng = np.random.default_rng(1)
    starts = X_STAR + 0.1 * rng.standard_normal((3, 2))
    fit = fit_return_map(simulate(a, X_STAR, starts, 6, 0.0, rng), equilibrium=X_STAR, bootstrap=0)
    np.testing.assert_allclose(fit.a_matrix, a, atol=1e-9)
    np.testing.assert_allclose(sorted_eigs(fit.eigenvalues), sorted_eigs(expected), atol=1e-9)
    assert fit.spectral_radius == pytest.approx(max(abs(np.asarray(expected))), abs=1e-9)
    assert fit.residual_rms < 1e-12
    assert fit.n_pairs == 15 and fit.n_sequences == 3


@pytest.mark.parametrize("a, radius", [(real_map(0.378, -0.109), 0.378), (complex_map(0.14, 0.164), np.hypot(0.14, 0.164))])
def test_noisy_fit_with_default_equilibrium_and_several_sequences(a, radius):
    rng = np.random.default_rng(7)
    starts = X_STAR + 0.05 * rng.standard_normal((8, 2))
    seqs = simulate(a, X_STAR, starts, 150, 0.01, rng)
    fit = fit_return_map(seqs, bootstrap=300, seed=3)
    assert fit.spectral_radius == pytest.approx(radius, abs=0.04)
    lo, hi = fit.spectral_radius_ci
    assert lo < radius < hi and hi - lo < 0.15
    np.testing.assert_allclose(fit.equilibrium, X_STAR, atol=0.01)
    assert fit.residual_rms == pytest.approx(0.01, rel=0.15)  # the noise we added
    # A complex pair stays complex, a real pair real.
    assert (abs(fit.eigenvalues.imag).max() > 0.05) == (abs(radius - 0.378) > 1e-9)


def test_pairs_are_never_formed_across_sequences():
    a = real_map(0.3, 0.1)
    rng = np.random.default_rng(2)
    far = [X_STAR + [1.0, 0.0], X_STAR + [0.0, -1.0], X_STAR + [-0.7, 0.6], X_STAR + [0.8, 0.8]]
    seqs = simulate(a, X_STAR, far, 2, 0.0, rng)
    x, y = section_pairs(seqs)
    assert len(x) == 4
    fit = fit_return_map(seqs, equilibrium=X_STAR, bootstrap=0)
    np.testing.assert_allclose(fit.a_matrix, a, atol=1e-9)
    # Joined into one run, the seams (last state of a run -> first of the next) spoil the fit.
    joined = fit_return_map([np.vstack(seqs)], equilibrium=X_STAR, bootstrap=0)
    assert np.abs(joined.a_matrix - a).max() > 0.1


def test_fit_is_deterministic_and_serialisable():
    rng = np.random.default_rng(4)
    seqs = simulate(complex_map(0.2, 0.1), X_STAR, X_STAR + 0.05 * rng.standard_normal((2, 2)), 40, 0.01, rng)
    one, two = fit_return_map(seqs, seed=5, bootstrap=50), fit_return_map(seqs, seed=5, bootstrap=50)
    assert one.to_dict() == two.to_dict()
    d = one.to_dict()
    assert len(d["eigenvalues"]) == 2 and d["eigenvalues"][0][1] == -d["eigenvalues"][1][1]


def test_bad_section_data_is_refused_with_a_reason():
    with pytest.raises(ValueError, match="at least 3 pairs"):
        fit_return_map([np.zeros((2, 2))])
    with pytest.raises(ValueError, match="dimension"):
        fit_return_map([np.zeros((3, 2)), np.zeros((3, 3))])
    with pytest.raises(ValueError, match="non-finite"):
        fit_return_map([np.array([[0.0, 1.0], [np.nan, 0.0], [1.0, 1.0], [0.0, 0.0]])])
    with pytest.raises(ValueError, match="do not span"):
        line = np.outer(np.arange(6.0), [1.0, 2.0])
        fit_return_map([line], equilibrium=[0.0, 0.0])
    with pytest.raises(TypeError):
        fit_return_map(np.zeros((5, 2)))
    with pytest.raises(ValueError, match="equilibrium"):
        fit_return_map([np.random.default_rng(0).standard_normal((6, 2))], equilibrium=[0.0])


def test_step_jacobian_of_a_known_nonlinear_map():
    # f(x) = x* + A (x - x*) + c * (x - x*)_0^2: at x* its Jacobian is A (the quadratic term vanishes).
    a = complex_map(0.14, 0.164)

    def step(x):
        d = x - X_STAR
        return X_STAR + a @ d + np.array([3.0, -2.0]) * d[0] ** 2

    jac = step_jacobian(step, X_STAR, 1e-4)
    np.testing.assert_allclose(jac["jacobian"], a, atol=1e-8)
    assert jac["spectral_radius"] == pytest.approx(np.hypot(0.14, 0.164), abs=1e-8)
    assert jac["fixed_point_residual"] == pytest.approx(0.0, abs=1e-14)
    # Forward differences carry the quadratic term's O(delta) error.
    fwd = step_jacobian(step, X_STAR, 1e-3, central=False)
    assert np.abs(fwd["jacobian"] - a).max() == pytest.approx(3e-3, rel=1e-3)


def test_step_jacobian_reports_a_failed_step():
    with pytest.raises(RuntimeError, match="failed"):
        step_jacobian(lambda x: None if x[0] > 0.5 else x, np.array([0.5, 0.0]), 0.01)
    with pytest.raises(ValueError, match="deltas"):
        step_jacobian(lambda x: x, np.zeros(2), 0.0)


def test_complex_list_orders_by_modulus():
    assert complex_list(np.array([0.1, -0.5 + 0.2j])) == [[-0.5, 0.2], [0.1, 0.0]]
