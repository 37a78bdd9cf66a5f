"""dicestack: imitation learning for dynamic dice stacking, from Python.

The world as a Gymnasium environment (DiceStackEnv, DiceStackVectorEnv), the automatic experts,
demonstrations as numpy arrays, training, evaluation and the leaderboard with dicestack's C++
learners and its regressors or Python ones (register_regressor). See docs/python.md.
"""
from . import _dicestack
from ._world import default_world
from .demos import Episode, load_demos, save_demos, view_dataset
from .env import DiceStackEnv
from .models import Expert, Model, Policy, evaluate, expert, leaderboard, load_model, train
from .regressors import register_regressor, regressor_names
from .vector_env import DiceStackVectorEnv

__version__ = _dicestack.__version__
Snapshot = _dicestack.Snapshot

__all__ = [
    "DiceStackEnv",
    "DiceStackVectorEnv",
    "Episode",
    "Expert",
    "Model",
    "Policy",
    "Snapshot",
    "default_world",
    "evaluate",
    "expert",
    "leaderboard",
    "load_demos",
    "load_model",
    "register_regressor",
    "regressor_names",
    "save_demos",
    "train",
    "view_dataset",
]

ENV_ID = "dicestack/DiceStack-v0"
ARM_ENV_ID = "dicestack/DiceStackArm-v0"  # the same task, the cup held by a planar arm (docs/arm.md)


def _register_with_gymnasium():
    try:
        from gymnasium.envs.registration import register, registry
    except ImportError:
        return
    # The environment ends its own episodes at the world's time limit: no TimeLimit wrapper.
    for env_id, kwargs in ((ENV_ID, {}), (ARM_ENV_ID, {"embodiment": "arm"})):
        if env_id not in registry:
            register(
                id=env_id,
                entry_point="dicestack.env:DiceStackEnv",
                vector_entry_point="dicestack.vector_env:DiceStackVectorEnv",
                max_episode_steps=None,
                kwargs=kwargs,
            )


_register_with_gymnasium()
