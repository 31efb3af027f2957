"""The perceived safe zone from Python: scikit-learn's names, agreement with
scikit-learn's linear discriminant analysis, online updates and JSON."""

from __future__ import annotations

import numpy as np
import pytest

import palc
from conftest import ZONE_SAMPLES


def samples() -> tuple[np.ndarray, np.ndarray]:
    data = np.loadtxt(ZONE_SAMPLES, delimiter=",", skiprows=1)
    return data[:, :6], data[:, 6]


def blobs(seed: int = 3, n: int = 200) -> tuple[np.ndarray, np.ndarray]:
    """Two Gaussian classes with a shared, full covariance (no ridge needed)."""
    rng = np.random.default_rng(seed)
    a = rng.normal(size=(6, 6))
    cov = a @ a.T + 6 * np.eye(6)
    x0 = rng.multivariate_normal(np.zeros(6), cov, size=n)
    x1 = rng.multivariate_normal(np.full(6, 2.0), cov, size=n + 37)
    X = np.vstack([x0, x1])
    y = np.concatenate([np.zeros(n), np.ones(n + 37)])
    return X, y


def reference_lda(X: np.ndarray, y: np.ndarray, Q: np.ndarray) -> np.ndarray:
    """p(y=1|x) of maximum-likelihood LDA (Eqs. 5-8), written out with NumPy."""
    means = [X[y == c].mean(axis=0) for c in (0, 1)]
    priors = [np.mean(y == c) for c in (0, 1)]
    centred = np.vstack([X[y == c] - means[c] for c in (0, 1)])
    cov = centred.T @ centred / len(X)
    inv = np.linalg.inv(cov)
    odds = [
        Q @ inv @ means[c] - 0.5 * means[c] @ inv @ means[c] + np.log(priors[c]) for c in (0, 1)
    ]
    return 1.0 / (1.0 + np.exp(odds[0] - odds[1]))


def test_predict_proba_agrees_with_linear_discriminant_analysis() -> None:
    X, y = blobs()
    model = palc.ZoneModel(ridge=0.0).fit(X, y)
    Q, _ = blobs(seed=11, n=50)
    proba = model.predict_proba(Q)
    assert proba.shape == (len(Q), 2)
    assert np.allclose(proba.sum(axis=1), 1.0)
    assert np.allclose(proba[:, 1], reference_lda(X, y, Q), atol=1e-9)
    try:
        from sklearn.discriminant_analysis import LinearDiscriminantAnalysis
    except ImportError:
        return
    sk = LinearDiscriminantAnalysis(solver="lsqr").fit(X, y)
    assert np.allclose(proba, sk.predict_proba(Q), atol=1e-9)
    assert np.array_equal(model.predict(Q), sk.predict(Q).astype(np.int64))


def test_update_equals_a_batch_fit_on_all_samples() -> None:
    X, y = blobs()
    order = np.random.default_rng(5).permutation(len(X))
    X, y = X[order], y[order]
    online = palc.ZoneModel()
    for part in np.array_split(np.arange(len(X)), 4):
        online.update(X[part], y[part])
    batch = palc.ZoneModel().fit(X, y)
    assert np.allclose(online.predict_proba(X), batch.predict_proba(X), atol=1e-9)


def test_predict_and_decision_function_agree_with_the_posterior() -> None:
    X, y = samples()
    model = palc.ZoneModel().fit(X, y)
    assert list(model.classes_) == [0, 1]
    assert model.n_features_in_ == 6
    assert model.is_informative
    proba = model.predict_proba(X)
    labels = model.predict(X)
    assert labels.dtype == np.int64
    assert np.array_equal(labels, (proba[:, 1] > proba[:, 0]).astype(np.int64))
    odds = model.decision_function(X)
    finite = np.abs(odds) < 30
    assert np.allclose(1 / (1 + np.exp(-odds[finite])), proba[finite, 1], atol=1e-9)


def test_json_round_trips_the_model() -> None:
    X, y = samples()
    model = palc.ZoneModel().fit(X, y)
    again = palc.ZoneModel.from_json(model.to_json())
    assert np.array_equal(again.predict_proba(X), model.predict_proba(X))
    assert again.config == model.config


def test_lateral_bounds_lie_in_the_lateral_range() -> None:
    X, y = samples()
    model = palc.ZoneModel().fit(X, y)
    k = 20
    s = np.linspace(0.0, 30.0, k)
    bounds = model.lateral_bounds(
        ego_s=s,
        reference_l=np.linspace(0.0, 3.5, k),
        ego_speed=np.full(k, 20.0),
        preceding=np.column_stack([s + 30.0, np.zeros(k)]),
        adjacent=np.column_stack([s - 10.0, np.full(k, 3.5)]),
    )
    assert bounds.shape == (k, 2)
    finite = np.isfinite(bounds)
    assert np.all(bounds[finite] >= -1.75 - 1e-9) and np.all(bounds[finite] <= 5.25 + 1e-9)
    constrained = finite.all(axis=1)
    assert np.all(bounds[constrained, 0] <= bounds[constrained, 1])


def test_an_empty_model_leaves_the_lateral_range_unconstrained() -> None:
    k = 3
    bounds = palc.ZoneModel().lateral_bounds(
        np.zeros(k), np.zeros(k), np.full(k, 20.0), np.zeros((k, 2)), np.zeros((k, 2))
    )
    assert np.all(bounds[:, 0] == -np.inf) and np.all(bounds[:, 1] == np.inf)


@pytest.mark.parametrize("dtype", [np.float32, np.int64])
def test_other_dtypes_and_strided_arrays_are_converted(dtype: type) -> None:
    X, y = samples()
    model = palc.ZoneModel().fit(X, y)
    converted = X.astype(dtype)
    strided = np.repeat(converted, 2, axis=1)[:, ::2]  # the same values, not C-contiguous
    assert not strided.flags["C_CONTIGUOUS"]
    expected = model.predict_proba(converted.astype(np.float64))
    assert np.array_equal(model.predict_proba(converted), expected)
    assert np.array_equal(model.predict_proba(strided), expected)
