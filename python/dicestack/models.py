"""Models, experts, training and evaluation: the same code paths as `dicestack train`,
`dicestack evaluate --json` and `dicestack record` (the C++ learners run with the GIL released)."""
import json
import os

from . import _dicestack
from ._world import resolve_world
from .demos import Episode, _records

Model = _dicestack.Model
Policy = _dicestack.Policy
Expert = _dicestack.Expert


def load_model(path):
    """A model file written by `dicestack train` or Model.save (FileNotFoundError if missing)."""
    return _dicestack.load_model(os.fspath(path))


def expert(name):
    """An automatic expert, "scripted" or "mpc": `expert(env)` (or `.act(env)`) gives the action
    for a DiceStackEnv's current state. It restarts by itself at each new episode; use one expert
    per world."""
    return _dicestack.Expert(name)


def _assignments(values, what):
    if not isinstance(values, dict):
        raise TypeError(f"{what} must be a dict of name: value, got {type(values).__name__}")
    out = []
    for key, value in values.items():
        if isinstance(value, bool):
            value = "true" if value else "false"
        out.append(f"{key}={value}")
    return out


def _demos_argument(demos):
    if isinstance(demos, (str, os.PathLike)):
        return os.fspath(demos)
    episodes = list(demos)
    if not all(isinstance(e, Episode) for e in episodes):
        raise TypeError("demos must be 'builtin', 'human', a folder, or a list of dicestack.Episode")
    return _records(episodes)


def train(regressor, learner="bc", demos="builtin", features=None, options=None, params=None, seed=0, out=None,
          *, world=None, split="episodes", threads=None):
    """Trains a model as `dicestack train` does and returns it (also written to `out` if given).

    regressor: a registry name (knn, linear_svr, rbf_svr, mlp, random_forest, gbt); params its
    settings ({"k": 5}). learner: bc, dagger, dad or dart; options its settings. features: the
    feature map (default: the learner's). demos: "builtin", "human", a folder or a list of
    Episodes. split "episodes" holds every fifth episode out (test error), "none" trains on all.
    The model's `training` dict holds train_error, test_error (if any) and seconds.
    """
    return _dicestack.train(
        resolve_world(world),
        _demos_argument(demos),
        regressor,
        _assignments(params or {}, "params"),
        learner,
        _assignments(options or {}, "options"),
        features or "",
        split,
        seed,
        threads,
        os.fspath(out) if out is not None else "",
    )


def evaluate(model, episodes=20, seed=0, *, world=None, demos=None, threads=None, initial_push="none"):
    """Rolls `model` out from `episodes` random starts, as `dicestack evaluate --json` does, and
    returns that command's object as a dict (stacked_rate, wall_contact_rate,
    realistic_success_rate, dice_in_cup_mean, ...; train_error and test_error when demos are
    given). The result does not depend on `threads`."""
    if not isinstance(model, Model):
        raise TypeError(f"model must be a dicestack.Model, got {type(model).__name__}")
    return json.loads(
        _dicestack.evaluate(
            model,
            resolve_world(world),
            episodes,
            seed,
            threads,
            initial_push,
            None if demos is None else _demos_argument(demos),
        )
    )
