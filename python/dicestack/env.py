"""DiceStackEnv: the dice-stacking world under the Gymnasium API (a gymnasium.Env when gymnasium
is importable). Stepping, rendering and snapshots run in C++ (_dicestack.Env)."""
import json

import numpy as np

from . import _dicestack
from ._spaces import box, gymnasium
from ._world import resolve_perturbation, resolve_world, world_dict


def check_seed(seed):
    """None, or an int in [0, 2^64 - 1] (TypeError / ValueError otherwise)."""
    if seed is None:
        return None
    if isinstance(seed, bool) or not isinstance(seed, (int, np.integer)):
        raise TypeError(f"seed must be an int or None, got {seed!r}")
    if not 0 <= int(seed) < 2**64:
        raise ValueError(f"seed must be a whole number in [0, 2^64 - 1], got {seed!r}")
    return int(seed)


class _NoGymnasiumEnv:
    """What gymnasium.Env gives DiceStackEnv, for when gymnasium is not installed."""

    metadata = {"render_modes": []}
    render_mode = None
    spec = None
    _np_random = None

    def reset(self, *, seed=None, options=None):
        if seed is not None:
            self._np_random = np.random.default_rng(seed)

    @property
    def np_random(self):
        if self._np_random is None:
            self._np_random = np.random.default_rng()
        return self._np_random

    @property
    def unwrapped(self):
        return self

    def close(self):
        pass

    def __enter__(self):
        return self

    def __exit__(self, *args):
        self.close()
        return False


_EnvBase = gymnasium.Env if gymnasium is not None else _NoGymnasiumEnv


class DiceStackEnv(_EnvBase):
    """The dice-stacking task (Keselman et al.) as a Gymnasium environment.

    Observation: the 24 state numbers as float64 (cup x, y, angle; per die x, y, angle, vx, vy,
    angular velocity; cup vx, vy, angular velocity; SI units), within `observation_space`.
    Action: the cup's velocity change (dvx m/s, dvy m/s, dw rad/s), clipped to `action_space`.
    Reward: minus the discounted scaled distance to the paper's goal stack. `terminated` is a
    realistic success (stacked, no wall touched) held for a few steps; `truncated` is the time
    limit (the world's episode.max_steps, 400 by default). `info` holds the outcome judge:
    dice_in_cup, dice_in_cup_now, stacked, stacked_steps, wall_contact, realistic_success, and t,
    distance, wall_contact_step.

    Seeding follows Gymnasium: reset(seed=s) starts from dicestack's random start s (the same as
    DiceEnv::reset(s) in C++); reset() without a seed continues a stream derived from the last
    seed. options={"state": 24 numbers} starts from a given state instead. start="paper" draws
    every start from the paper's instead (its pose at rest, the whole scene shifted in x by
    U(-2 cm, 2 cm)), as `dicestack evaluate --start paper`.

    perturb (docs/robustness.md): None, a level ("easy", "medium", "hard"), a
    perturbation file or a dict of its fields. Each episode then runs in the world drawn from its
    seed (frictions, masses, gravity, wider starts), its observations arrive late and noisy and
    its actions late, biased and noisy, exactly as `dicestack evaluate --perturb` runs it.
    options={"perturb": ...} perturbs that one episode instead. info["perturbation"] (at reset)
    holds the values drawn; `state` stays the true state.

    estimator: "none" (the observations as the sensors give them), "kalman" or "particle"
    ("particle:N" for N particles): under sensing factors each observation is the estimate of a
    Kalman filter, or a particle filter, whose motion model is the simulator, as `dicestack
    evaluate --estimator NAME` shows a policy (docs/robustness.md, "The estimator").

    embodiment: None (the world's), "cup" (the paper's floating cup) or "arm": a planar arm holds
    the cup and the same actions drive it through its joints (docs/arm.md); the observation stays
    the 24 numbers. `dicestack/DiceStackArm-v0` is this environment with embodiment="arm".

    controller: "cup" (the action is the cup's velocity change, on either embodiment) or
    "joint_torque" (the arm only: the action is the four joint torques in N m, shoulder first,
    held through the step and clipped to the arm's limits, which `action_space` gives). On the
    arm, info also holds link_angles and link_rates (each link's absolute direction and rate;
    under joint_torque behind the Kalman filter, those of the state it estimates) and joint_torques (what the joints held on average over the last step, N m).
    """

    metadata = {"render_modes": ["rgb_array"], "render_fps": 30}

    def __init__(self, world=None, render_mode=None, perturb=None, start="random", estimator="none", embodiment=None,
                 controller="cup"):
        if render_mode is not None and render_mode not in self.metadata["render_modes"]:
            raise ValueError(f"render_mode must be None or one of {self.metadata['render_modes']}, got {render_mode!r}")
        self._world = resolve_world(world, start, embodiment)
        if not isinstance(estimator, str):
            raise TypeError(f"estimator must be a name (none, kalman, particle), got {type(estimator).__name__}")
        if not isinstance(controller, str):
            raise TypeError(f"controller must be a name (cup, joint_torque), got {type(controller).__name__}")
        self._env = _dicestack.Env(self._world, resolve_perturbation(perturb, self._world), estimator, controller)
        self.render_mode = render_mode
        self.metadata = dict(type(self).metadata, render_fps=int(round(1.0 / self._world.control_dt)))
        self.observation_space = box(*self._env.observation_bounds())
        self.action_space = box(*self._env.action_bounds())

    def reset(self, *, seed=None, options=None):
        seed = check_seed(seed)
        super().reset(seed=seed)  # seeds self.np_random as Gymnasium expects; episodes use dicestack's seeds
        state = perturbation = None
        if options:
            unknown = set(options) - {"state", "perturb"}
            if unknown:
                raise ValueError(f"unknown reset option(s) {sorted(unknown)}; the options are 'state' and 'perturb'")
            state = options.get("state")
            if "perturb" in options:
                perturbation = resolve_perturbation(options["perturb"], self._world)
        obs, info = self._env.reset(seed, state, perturbation)
        if self._env.perturbed:
            info["perturbation"] = json.loads(self._env.draw)
        return obs, info

    def step(self, action):
        return self._env.step(action)

    def render(self):
        """An H x W x 3 uint8 RGB frame for render_mode="rgb_array" (None without a render mode)."""
        if self.render_mode == "rgb_array":
            return self._env.render()
        return None

    def close(self):
        pass  # nothing outside Python's memory to release

    def snapshot(self):
        """An exact, picklable copy of the environment (world, outcome, noise and seed stream)."""
        return self._env.snapshot()

    def restore(self, snapshot):
        """Continues bit for bit from `snapshot`; ValueError if it was taken in another world."""
        self._env.restore(snapshot)

    @property
    def state(self):
        """The current 24 state numbers (a copy)."""
        return self._env.state

    @property
    def t(self):
        """Control steps taken in this episode."""
        return self._env.t

    @property
    def pending(self):
        """Under an action delay of d steps, the (d, 3) actions that run before the next one chosen
        ((d, 4) in joint torques), in order (zeros before the first choice lands); none without a
        delay. A policy on an "/ahead" feature map takes it: policy.act(obs, pending=env.pending,
        unseen=env.unseen)."""
        return self._env.pending

    @property
    def unseen(self):
        """Under an observation delay, the actions that ran (as chosen) since the state the last
        observation shows, in order; (0, 3) without a delay. Four columns under joint_torque."""
        return self._env.unseen

    @property
    def world(self):
        """The world config as a dict (`dicestack config`'s format)."""
        return world_dict(self._world)

    @property
    def world_hash(self):
        return self._env.world_hash
