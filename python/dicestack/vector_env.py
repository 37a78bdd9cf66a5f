"""DiceStackVectorEnv: N environments stepped together in C++ on all cores with the GIL released
(envpool style), under Gymnasium's vector API (a gymnasium.vector.VectorEnv when importable)."""
import numbers

from . import _dicestack
from ._spaces import batch, box, gymnasium
from ._world import resolve_perturbation, resolve_world, world_dict
from .env import check_seed

if gymnasium is not None:
    _VectorBase = gymnasium.vector.VectorEnv
    try:
        _NEXT_STEP = gymnasium.vector.AutoresetMode.NEXT_STEP
    except AttributeError:  # gymnasium 1.0 has next-step autoreset only, without the enum
        _NEXT_STEP = "NextStep"
else:
    _VectorBase = object
    _NEXT_STEP = "NextStep"


class DiceStackVectorEnv(_VectorBase):
    """num_envs DiceStackEnvs stepped at once; gives exactly what stepping them one by one gives.

    reset(seed=s) seeds environment i with s + i (Gymnasium's rule; a list gives one seed per
    environment, None continues each one's stream) and returns obs (N x 24) and an info dict of
    arrays (with Gymnasium's "_key" masks). step(actions) takes an (N x 3) array and returns
    obs, rewards, terminated, truncated (arrays of N) and infos.

    Autoreset is Gymnasium 1.x's "next-step" mode: after an environment's episode ends, its
    next step() ignores its action, resets it (no seed: the next seed of its stream) and returns
    the first observation with reward 0 and terminated = truncated = False.

    perturb: as DiceStackEnv's; each environment draws its own world from its own episode seed.
    estimator: as DiceStackEnv's ("none", "kalman" or "particle"), one per environment.
    embodiment, controller: as DiceStackEnv's.
    """

    metadata = {"render_modes": [], "autoreset_mode": _NEXT_STEP}
    render_mode = None
    spec = None
    closed = False

    def __init__(self, num_envs, world=None, threads=None, perturb=None, start="random", estimator="none",
                 embodiment=None, controller="cup"):
        if isinstance(num_envs, bool) or not isinstance(num_envs, numbers.Integral) or num_envs < 1:
            raise ValueError(f"num_envs must be a whole number >= 1, got {num_envs!r}")
        if num_envs >= 2**63:
            raise ValueError(f"DiceStackVectorEnv: {num_envs} environments would need more memory than any machine has")
        self.num_envs = int(num_envs)
        self._world = resolve_world(world, start, embodiment)
        if not isinstance(estimator, str):
            raise TypeError(f"estimator must be a name (none, kalman, particle), got {type(estimator).__name__}")
        if not isinstance(controller, str):
            raise TypeError(f"controller must be a name (cup, joint_torque), got {type(controller).__name__}")
        self._vec = _dicestack.VectorEnv(self._world, self.num_envs, threads, resolve_perturbation(perturb, self._world),
                                         estimator, controller)
        probe = _dicestack.Env(self._world, controller=controller)
        obs_low, obs_high = probe.observation_bounds()
        act_low, act_high = probe.action_bounds()
        self.single_observation_space = box(obs_low, obs_high)
        self.single_action_space = box(act_low, act_high)
        self.observation_space = batch(obs_low, obs_high, self.num_envs)
        self.action_space = batch(act_low, act_high, self.num_envs)

    def reset(self, *, seed=None, options=None):
        if options:
            raise ValueError(f"DiceStackVectorEnv.reset takes no options, got {options!r}")
        if seed is None:
            seeds = [None] * self.num_envs
        elif isinstance(seed, (list, tuple)):
            if len(seed) != self.num_envs:
                raise ValueError(f"reset needs {self.num_envs} seeds, got {len(seed)}")
            seeds = [check_seed(s) for s in seed]
        else:
            first = check_seed(seed)
            if first + self.num_envs > 2**64:
                raise ValueError(f"seed {seed} + {self.num_envs} environments passes 2^64 - 1")
            seeds = [first + i for i in range(self.num_envs)]
        if gymnasium is not None:
            super().reset(seed=seed if isinstance(seed, int) else None)
        return self._vec.reset(seeds)

    def step(self, actions):
        return self._vec.step(actions)

    def close(self, **kwargs):
        self.closed = True

    @property
    def pending(self):
        """Per environment, the (d, 3) actions ((d, 4) in joint torques) that run before its next
        one under an action delay (DiceStackEnv.pending); (0, 3) or (0, 4) arrays without a delay."""
        return self._vec.pending

    @property
    def unseen(self):
        """Per environment, the actions that ran since the state its observation shows
        (DiceStackEnv.unseen)."""
        return self._vec.unseen

    @property
    def world(self):
        """The world config as a dict (`dicestack config`'s format)."""
        return world_dict(self._world)
