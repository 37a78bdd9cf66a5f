"""Python regressors: any object with scikit-learn's fit(X, Y) / predict(X) as a regressor of
dicestack's registry, usable by every learner and the leaderboard in this process.

The C++ side (a Regressor subclass in _dicestack) calls the functions below with the GIL held:
fitting, predicting (one row at a time in rollouts, so Python regressors serialise on the GIL),
pickling. A fitted model is saved as the model file plus MODEL.pkl (the pickled estimator);
reading the pickle runs code, so only load_model(path, allow_pickle=True) does.
"""
import pickle

import numpy as np

from . import _dicestack

_TYPES = {bool: "boolean", int: "integer", float: "real"}


def register_regressor(name, factory, *, description=None, params=None):
    """Registers `factory` as the regressor `name`.

    factory(**params) must return a fresh, unfitted object with fit(X, Y) and predict(X) (a
    scikit-learn estimator, a Pipeline, a class of your own): X is N x d standardised feature
    rows, Y is N x 3 standardised actions (N x 4 for a /torque or /osc map), predict returns the same shape (multi-output: wrap a
    single-output estimator in sklearn.multioutput.MultiOutputRegressor). If the object has a
    `random_state` parameter left at None, it is set from the training seed, so that the same
    data and seed give the same model.

    params: optional {name: default} of bool, int or float values: the regressor's parameters,
    set per run with train(..., params={...}) and recorded in the model file. description:
    one line for listings (default: the factory's name).

    Raises ValueError if the name is taken (a built-in, a plugin or an earlier registration).
    Register before training starts in other threads: the registry is not locked.
    """
    if not isinstance(name, str) or not name:
        raise TypeError(f"name must be a non-empty str, got {name!r}")
    if not callable(factory):
        raise TypeError(f"factory must be callable (a class or function returning an estimator), got {factory!r}")
    schema = []
    for key, default in (params or {}).items():
        kind = _TYPES.get(type(default))
        if not isinstance(key, str) or kind is None:
            raise TypeError(f"regressor {name}: parameter {key!r} must have a bool, int or float default, "
                            f"got {default!r}")
        text = ("true" if default else "false") if kind == "boolean" else repr(default)
        schema.append((key, kind, text))
    if description is None:
        description = "Python: " + getattr(factory, "__qualname__", type(factory).__name__)
    _dicestack.register_regressor(name, factory, str(description), schema)


def regressor_names():
    """Every registered regressor: the built-ins, plugins and Python registrations, sorted."""
    return _dicestack.regressor_names()


# ---- called from C++ with the GIL held ----------------------------------------------------------

def _fit(name, factory, params, x, y, seed):
    estimator = factory(**params)
    for method in ("fit", "predict"):
        if not callable(getattr(estimator, method, None)):
            raise TypeError(f"regressor {name}: its factory returned {type(estimator).__name__}, which has no "
                            f"{method}() method")
    get_params = getattr(estimator, "get_params", None)
    if callable(get_params):
        try:
            if "random_state" in get_params(deep=False) and get_params(deep=False)["random_state"] is None:
                estimator.set_params(random_state=seed % 2**32)
        except (TypeError, ValueError, AttributeError):
            pass
    estimator.fit(x, y)
    return estimator


def _predict(name, estimator, x, outputs):
    y = np.asarray(estimator.predict(x), dtype=np.float64)
    n = x.shape[0]
    if y.shape != (n, outputs):
        if y.size != n * outputs:
            raise ValueError(f"regressor {name}: predict returned shape {y.shape} for {n} rows; expected ({n}, {outputs})"
                             " (a single-output estimator needs sklearn.multioutput.MultiOutputRegressor)")
        y = y.reshape(n, outputs)
    if not np.isfinite(y).all():
        raise ValueError(f"regressor {name}: predict returned NaN or infinity")
    return np.ascontiguousarray(y)


def _dumps(estimator):
    return pickle.dumps(estimator, protocol=pickle.HIGHEST_PROTOCOL)


def _loads(data):
    return pickle.loads(data)


def _type_name(estimator):
    t = type(estimator)
    return f"{t.__module__}.{t.__qualname__}"
