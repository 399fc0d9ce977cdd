"""The population Kalman filter through Python, against filterpy and closed forms."""
import numpy as np
import pytest

import recruit

from conftest import ROOT

filterpy_kalman = pytest.importorskip("filterpy.kalman")


def _stochastic(rng, m):
    A = rng.uniform(0.05, 1.0, (m, m))
    return A / A.sum(axis=0)


def _centre(P):
    # Onto 1^T P = 0: the total N is known exactly, so a valid belief has no variance along 1.
    m = P.shape[0]
    Pi = np.eye(m) - np.ones((m, m)) / m
    return Pi @ P @ Pi


def _linear_problem(seed, m, r):
    rng = np.random.default_rng(seed)
    N = 100
    A = _stochastic(rng, m)
    H = rng.normal(size=(r, m))
    L = rng.normal(size=(r, r))
    R = L @ L.T + r * np.eye(r)
    # Process noise moving agents between states: columns e_i - e_{i+1} sum to zero.
    G = np.zeros((m, m - 1))
    for i in range(m - 1):
        G[i, i], G[i + 1, i] = 1.0, -1.0
    Qw = np.diag(rng.uniform(0.1, 1.0, m - 1))
    x0 = rng.dirichlet(np.ones(m)) * N
    S = rng.normal(size=(m, m))
    P0 = _centre(S @ S.T)
    ys = rng.normal(size=(60, r)) * 3 + H @ x0
    return dict(N=N, A=A, H=H, R=R, G=G, Qw=Qw, x0=x0, P0=P0, ys=ys)


@pytest.mark.parametrize("m,r", [(2, 1), (4, 1), (5, 2), (20, 3)])
def test_plain_mode_equals_filterpy(m, r):
    # With no Qz (mode "plain") and Q = G Qw G^T, the population filter is the standard Kalman
    # filter (docs/equations.md); filterpy's KalmanFilter is an independent implementation.
    p = _linear_problem(m * 10 + r, m, r)
    model = recruit.FilterModel.linear(p["H"], p["R"], p["N"], x0=p["x0"], P0=p["P0"],
                                       A=p["A"], G=p["G"], Qw=p["Qw"])
    kf = recruit.KalmanFilter(model, "plain")
    ref = filterpy_kalman.KalmanFilter(dim_x=m, dim_z=r)
    ref.x = p["x0"].copy()
    ref.P = p["P0"].copy()
    ref.F = p["A"]
    ref.H = p["H"]
    ref.R = p["R"]
    ref.Q = p["G"] @ p["Qw"] @ p["G"].T
    for k, y in enumerate(p["ys"]):
        if k > 0:
            kf.predict(p["A"])
            ref.predict()
        if k % 7 != 3:  # every 7th sample missing: predict only
            assert kf.update(y)
            ref.update(y)
        else:
            assert not kf.update(np.full(r, np.nan))
        scale = 1.0 + np.abs(ref.P).max()
        np.testing.assert_allclose(kf.x, ref.x, rtol=0, atol=1e-10 * scale)
        np.testing.assert_allclose(kf.P, ref.P, rtol=0, atol=1e-10 * scale)


def test_run_equals_step_by_step_with_missing_samples():
    p = _linear_problem(3, 4, 2)
    model = recruit.FilterModel.linear(p["H"], p["R"], p["N"], x0=p["x0"], P0=p["P0"],
                                       A=p["A"], G=p["G"], Qw=p["Qw"])
    ys = p["ys"].copy()
    ys[[2, 5, 6]] = np.nan
    X, V = recruit.KalmanFilter(model, "extended").run(ys)
    kf = recruit.KalmanFilter(model, "extended")
    for k, y in enumerate(ys):
        if k > 0:
            kf.predict(p["A"])
        kf.update(None if np.isnan(y).all() else y)
        np.testing.assert_array_equal(X[k], kf.x)
        np.testing.assert_array_equal(V[k], np.diag(kf.P))
    assert X.shape == V.shape == (len(ys), 4)


def test_extended_and_conservative_predict_closed_forms():
    # From a known state (P0 = 0) one prediction gives P = Qz: eq. (26)
    # diag(A x) - A diag(x) A^T (extended) and N (diag(A 1) - A A^T) (conservative).
    rng = np.random.default_rng(5)
    m, N = 5, 60
    A = _stochastic(rng, m)
    x0 = np.array([20.0, 10.0, 0.0, 25.0, 5.0])
    model = recruit.FilterModel.linear(np.ones((1, m)), [[1.0]], N, x0=x0)
    ext = recruit.KalmanFilter(model, "extended")
    ext.predict(A)
    np.testing.assert_allclose(ext.P, np.diag(A @ x0) - A @ np.diag(x0) @ A.T, atol=1e-12)
    np.testing.assert_allclose(ext.x, A @ x0, atol=1e-12)
    con = recruit.KalmanFilter(model, "conservative")
    con.predict(A)
    one = np.ones(m)
    np.testing.assert_allclose(con.P, N * (np.diag(A @ one) - A @ A.T), atol=1e-12)
    pla = recruit.KalmanFilter(model, "plain")
    pla.predict(A)
    np.testing.assert_allclose(pla.P, 0.0, atol=1e-12)


def test_two_state_broadcast_matrix_and_predict():
    # The two-state model: A = [[1 - p_on, p_off], [p_on, 1 - p_off]] (docs/equations.md).
    model = recruit.FilterModel.two_state(60, 0.5, 0.45, 0.3)
    np.testing.assert_allclose(model.broadcast_matrix(0.2, 0.1), [[0.8, 0.1], [0.2, 0.9]])
    kf = recruit.KalmanFilter(model, "extended")
    kf.predict_broadcast(0.25, 0.0)
    np.testing.assert_allclose(kf.x, [45.0, 15.0], atol=1e-12)
    # Binomial variance of the count switched on: N p (1 - p).
    np.testing.assert_allclose(kf.P, 60 * 0.25 * 0.75 * np.array([[1, -1], [-1, 1]]), atol=1e-12)


def test_filter_log_matches_run_on_the_shipped_log(root):
    model_path = root / "models" / "filter" / "three_state_model.json"
    log_path = root / "models" / "filter" / "three_state_log.csv"
    out = recruit.filter_log(model_path, log_path, "extended")
    log = np.genfromtxt(log_path, delimiter=",", names=True)
    model = recruit.FilterModel.load(str(model_path))
    ys = log["y"].reshape(-1, 1)
    X, V = recruit.KalmanFilter(model).run(ys, log["p_on"], log["p_off"])
    for i, name in enumerate(model.state_names):
        np.testing.assert_allclose(out["x_" + name], X[:, i], rtol=1e-15, atol=1e-12)
        np.testing.assert_allclose(out["var_" + name], V[:, i], rtol=1e-15, atol=1e-12)
    exact = recruit.filter_log(model_path, log_path, "exact")
    assert np.allclose(exact["x_off"] + exact["x_warming"] + exact["x_on"], 60.0)


def test_bad_inputs_raise_value_error(root):
    model = recruit.FilterModel.two_state(60, 0.5, 0.45, 0.3)
    with pytest.raises(ValueError, match="bogus"):
        recruit.KalmanFilter(model, "bogus")
    kf = recruit.KalmanFilter(model)
    with pytest.raises(ValueError, match="measurement: must have 1 entries, got 2"):
        kf.update([1.0, 2.0])
    with pytest.raises(ValueError, match="finite"):
        kf.update([np.inf])
    with pytest.raises(ValueError, match="column"):
        kf.predict([[0.5, 0.5], [0.6, 0.5]])
    with pytest.raises(ValueError, match="2-D"):
        kf.predict(np.ones((2, 2, 2)))
    with pytest.raises(ValueError, match="probability"):
        kf.predict_broadcast(1.5, 0.0)
    with pytest.raises(ValueError, match="x0 must sum to N"):
        recruit.KalmanFilter(model, "plain", x0=[1.0, 2.0])
    with pytest.raises(ValueError, match="no_such_model.json"):
        recruit.FilterModel.load(str(root / "no_such_model.json"))
    with pytest.raises(ValueError, match="zero column sums"):
        recruit.FilterModel.linear(np.ones((1, 2)), [[1.0]], 10, G=[[1.0], [1.0]])
    with pytest.raises(ValueError, match="R: must be positive definite"):
        recruit.FilterModel.linear(np.ones((1, 2)), [[-1.0]], 10)
    linear = recruit.FilterModel.linear(np.ones((1, 2)), [[1.0]], 10)
    with pytest.raises(ValueError, match="not 'broadcast'"):
        recruit.KalmanFilter(linear).predict_broadcast(0.1, 0.1)
    with pytest.raises(ValueError, match=r"ys: must be T x 1 .*got 1 x 2"):
        recruit.KalmanFilter(model).run([[1.0, 2.0]])
    two = recruit.FilterModel.linear(np.eye(2), np.eye(2), 10, A=np.eye(2))
    with pytest.raises(ValueError, match="partly NaN"):
        recruit.KalmanFilter(two).run([[1.0, np.nan]])
    with pytest.raises(ValueError, match="some entries are NaN"):
        recruit.KalmanFilter(two).update([1.0, np.nan])
