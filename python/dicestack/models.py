"""Models, experts, training, evaluation and the leaderboard: the same code paths as `dicestack
train`, `dicestack evaluate --json`, `dicestack leaderboard` and `dicestack record` (the C++
learners run with the GIL released). Long calls draw a progress bar on stderr and stop on Ctrl-C
(KeyboardInterrupt), leaving no half-written output."""
import json
import os

from . import _dicestack
from ._progress import progress_bar
from ._world import perturbation_name, resolve_perturbation, resolve_world
from .demos import Episode, _records

Model = _dicestack.Model
Policy = _dicestack.Policy
Expert = _dicestack.Expert


def load_model(path, allow_pickle=False):
    """A model file written by `dicestack train` or Model.save (FileNotFoundError if missing).

    A model of a Python regressor (register_regressor) keeps its estimator pickled in
    PATH.pkl. Unpickling runs code, so such a model is read only with allow_pickle=True, and
    should be only from a source you trust; without it, ValueError says so. The pickle must be
    the one saved with the model file (its size and FNV-1a are recorded there). Loading it needs
    no register_regressor call in this process, only the estimator's classes importable.
    """
    if not isinstance(allow_pickle, bool):
        raise TypeError(f"allow_pickle must be True or False, got {type(allow_pickle).__name__}")
    return _dicestack.load_model(os.fspath(path), allow_pickle)


def expert(name, demos=None, *, world=None, seed=0, retry=False, preset="plain", settings=None):
    """An automatic expert, "scripted", "mpc" or "tracker": `expert(env)` (or `.act(env)`) gives
    the action for a DiceStackEnv's current state. It restarts by itself at each new episode; use
    one expert per world.

    "tracker" is the demonstrator made of demonstrations: it follows the recorded cup path of
    `demos` ("builtin", "human", a folder or a list of Episodes) that succeeds when simulated
    from the episode's start, chosen once per episode. Its recordings are ranked in `world` with
    `seed` when it is made (a few seconds). The other experts read no demonstrations.

    retry=True ("mpc", "tracker"): once a failed attempt has come to rest (dice still, not
    stacked, the lowest on the table), start afresh from there, as the "+retry" feature maps
    expect. The expert must then be asked at every step of an episode.

    preset and settings ("tracker"): its named settings, "plain" or "distill" (the learners'
    default), and a dict of settings on top, by the names of the learners' tracker_* options
    without "tracker_" (e.g. {"smooth": 4, "paths": 3}; docs/expert.md)."""
    if not isinstance(retry, bool):
        raise TypeError(f"retry must be True or False, got {type(retry).__name__}")
    if name == "tracker" and demos is None:
        raise ValueError('expert "tracker" follows recordings: give them with demos= ("builtin", "human", a folder '
                         "or a list of Episodes)")
    return _dicestack.Expert(name, None if demos is None else _demos_argument(demos), resolve_world(world), seed, retry,
                             preset, [] if settings is None else _assignments(settings, "settings"))


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
    what = "demos must be 'builtin', 'human', a folder, or a list of dicestack.Episode"
    try:
        episodes = list(demos)
    except TypeError:
        raise TypeError(f"{what}, got {type(demos).__name__}") from None
    for i, e in enumerate(episodes):
        if not isinstance(e, Episode):
            raise TypeError(f"{what}; item {i} is a {type(e).__name__}")
    return _records(episodes)


def train(regressor, learner="bc", demos="builtin", features=None, options=None, params=None, seed=0, out=None,
          *, world=None, start="random", split="episodes", threads=None, progress=None):
    """Trains a model as `dicestack train` does and returns it (also written to `out` if given).

    regressor: a registry name (knn, linear_svr, rbf_svr, mlp, random_forest, gbt, or one added
    with register_regressor); params its settings ({"k": 5}). learner: bc, dagger, dad or dart;
    options its settings. features: the feature map (default: the learner's). demos: "builtin",
    "human", a folder or a list of Episodes. split "episodes" holds every fifth episode out (test
    error), "none" trains on all. The model's `training` dict holds train_error, test_error (if
    any) and seconds. start: where training episodes start, "random" or "paper" (as `train --start`).
    progress: draw a progress bar on stderr (None: when stderr is a terminal).
    Ctrl-C stops the training with KeyboardInterrupt; `out` is then left as it was.
    """
    return _dicestack.train(
        resolve_world(world, start),
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
        progress_bar(progress),
    )


def _estimator_name(estimator):
    if estimator is None:
        return ""  # each model's own
    if not isinstance(estimator, str):
        raise TypeError(f"estimator must be a name (none, kalman, particle), got {type(estimator).__name__}")
    return estimator


def evaluate(model, episodes=20, seed=0, *, world=None, start="random", demos=None, threads=None,
             initial_push="none", perturb=None, estimator=None, report=None, progress=None):
    """Rolls `model` out from `episodes` starts (start: "random", or "paper" for the paper's start
    shifted by up to 2 cm, as `evaluate --start`), as `dicestack evaluate --json` does, and
    returns that command's object as a dict (stacked_rate, wall_contact_rate,
    realistic_success_rate, dice_in_cup_mean, ...; train_error and test_error when demos are
    given). The result does not depend on `threads`. perturb: as `evaluate --perturb` (a level,
    a perturbation file or a dict of its fields; docs/robustness.md); estimator: what the policy is
    shown under sensing factors and delays, as `evaluate --estimator` ("none", "kalman" or "particle"; None: the
    model's own, the one a policy trained with perturb= names, else none). progress: a progress bar on
    stderr (None: when stderr is a terminal); Ctrl-C stops the rollouts with KeyboardInterrupt.

    report: a folder to write the results page of `dicestack evaluate --report DIR` into:
    index.html (the row, previews of a successful and a failed rollout), index_files/ (per-episode
    results as LeRobot's eval_info.json) and dicestack-report.json (docs/results-pages.md). It is
    written whole, replacing only a report dicestack wrote; anything else there is refused with
    ValueError before any rollout, and left untouched."""
    if not isinstance(model, Model):
        raise TypeError(f"model must be a dicestack.Model, got {type(model).__name__}")
    if report is not None and not isinstance(report, (str, os.PathLike)):
        raise TypeError(f"report must be a folder path, got {type(report).__name__}")
    w = resolve_world(world, start)
    perturbation = resolve_perturbation(perturb, w)
    return json.loads(
        _dicestack.evaluate(
            model,
            w,
            episodes,
            seed,
            threads,
            initial_push,
            None if demos is None else _demos_argument(demos),
            progress_bar(progress),
            perturbation,
            perturbation_name(perturb),
            os.fspath(report) if report is not None else "",
            _estimator_name(estimator),
        )
    )


_FORMATS = dict(_dicestack.leaderboard_formats())  # file suffix -> format, from the library's table


def _names(values, what):
    if values is None:
        return []
    if isinstance(values, str):
        return [v for v in values.split(",") if v]
    values = list(values)
    if not all(isinstance(v, str) for v in values):
        raise TypeError(f"{what} must be a str or a list of str")
    return values


def leaderboard(regressors=None, learners=None, demos="builtin", *, features=None, options=None, baselines=None,
                profile="quick", split="episodes", episodes=None, seeds=1, seed=0, world=None, start="random",
                threads=None, out=None, format=None, perturb=None, estimator=None, embodiment=None, controller="cup",
                progress=None):
    """The paper's Table I, as `dicestack leaderboard` makes it: every regressor under every
    learner (and feature map), rolled out from random starts. Returns the rows as a list of dicts
    with the keys of `dicestack leaderboard --format json`'s rows (regressor, learner, features,
    train_error, test_error, dice_in_cup_mean, episodes, stacked, wall_contact,
    realistic_success, the rates and their *_ci95 intervals, fit_s, us_per_step; -1 where a
    value does not apply, as in the command line's table).

    regressors: names (None: every registered one, Python regressors included); learners: None
    (bc, dagger, dart) or names; features: feature maps (None: each learner's own); options: a
    dict of learner options applied to every learner that has the key; baselines: names
    (cmaes, de, basinhop, bayes, reinforce, rrt) or "all"; profile "quick" or "paper"; split
    "episodes" or "rows"; episodes: rollouts per row and seed (None: 20 quick, 100 paper);
    seeds: training seeds per row. demos: "builtin", "human" or a folder. start: "random" or
    "paper", where training and rollouts start (as `leaderboard --start`). perturb: roll out in
    perturbed worlds, as `leaderboard --perturb` (a level or a perturbation file; training stays
    nominal; docs/robustness.md); estimator: what the rolled-out policies are shown under sensing
    factors and delays, as `leaderboard --estimator` ("none", "kalman" or "particle"; None: each model's
    own). embodiment: "cup" or "arm" (None: the world's); controller: "cup" or "joint_torque", what
    the rows' policies answer, as `leaderboard --controller` (joint torques need the arm; docs/arm.md).

    out: also write the table there, in `format` (md, csv, latex, json or html; None: from the
    file's suffix, .md .csv .tex .json .html, else md; html is a results page with its media in
    <stem>_files/ beside it, docs/results-pages.md), atomically and never over a file that is not a
    dicestack leaderboard; finished rows are kept in OUT.partial.json, so an interrupted run
    (Ctrl-C: KeyboardInterrupt) resumes where it stopped when called again with the same settings.
    progress: a progress bar on stderr (None: when stderr is a terminal).
    """
    if format is None:
        format = _FORMATS.get(os.path.splitext(os.fspath(out))[1].lower(), "md") if out is not None else "md"
    if not isinstance(demos, (str, os.PathLike)):
        raise TypeError("demos must be 'builtin', 'human' or a folder")
    if perturb is not None and not isinstance(perturb, (str, os.PathLike)):
        raise TypeError("perturb must be a level (none, easy, medium, hard) or a perturbation file")
    for name, value in (("episodes", episodes), ("seeds", seeds)):
        if value is not None and (isinstance(value, bool) or not isinstance(value, int) or value < 1):
            raise ValueError(f"{name} must be a positive int, got {value!r}")
    if not isinstance(controller, str):
        raise TypeError(f"controller must be a name (cup, joint_torque), got {type(controller).__name__}")
    table = _dicestack.leaderboard(
        resolve_world(world, start, embodiment),
        os.fspath(demos),
        _names(regressors, "regressors"),
        _names(learners, "learners"),
        _assignments(options or {}, "options"),
        _names(baselines, "baselines"),
        _names(features, "features"),
        profile,
        split,
        episodes or 0,
        seeds,
        seed,
        threads,
        os.fspath(out) if out is not None else "",
        format,
        progress_bar(progress),
        "none" if perturb is None else os.fspath(perturb),
        _estimator_name(estimator),
        controller,
    )
    return json.loads(table)["rows"]
