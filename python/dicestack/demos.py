"""Demonstrations: episodes with numpy arrays, read from and written to dicestack's folder format
(one CSV per episode plus meta.json; docs/datasets.md) by the C++ library, which checks every
value and never replaces a folder that is not a dicestack set; and the episode viewer page."""
import os
from dataclasses import dataclass

import numpy as np

from . import _dicestack
from ._world import resolve_world

SOURCES = ("human", "expert", "policy", "correction")


@dataclass
class Episode:
    """One demonstration: T states (before each action) and the T actions taken in them (T x 3,
    the cup's; or T x 4, an arm's joint torques).

    `sources` says who chose each action (human, expert, policy or correction; default: policy);
    the outcome fields are what the judge saw over the whole episode. Format v2's transitions:
    `final_state` (the state after the last action, shape (24,)), `rewards` (T) and the end flags
    `terminated` / `truncated`; `final_state` and `rewards` are None where unknown (a format-v1
    set whose final state could not be recovered by replay). On the arm (format v4):
    `link_angles` and `link_rates` (T x 3, each link's absolute angle and rate before each
    action), `joint_torques` (T x 4, N m, what the joints held over each step) and
    `final_link_angles` / `final_link_rates` (3 each, after the last action); None elsewhere.
    """

    states: np.ndarray
    actions: np.ndarray
    sources: list = None
    name: str = ""
    seed: int = 0
    origin: str = ""
    steps: int = 0
    dice_in_cup: int = 0
    dice_in_cup_now: int = 0
    stacked: bool = False
    stacked_steps: int = 0
    wall_contact: bool = False
    final_state: np.ndarray = None
    rewards: np.ndarray = None
    terminated: bool = False
    truncated: bool = False
    link_angles: np.ndarray = None
    link_rates: np.ndarray = None
    joint_torques: np.ndarray = None
    final_link_angles: np.ndarray = None
    final_link_rates: np.ndarray = None

    _ARM_FIELDS = ("link_angles", "link_rates", "joint_torques", "final_link_angles", "final_link_rates")

    def __post_init__(self):
        for field in self._ARM_FIELDS:
            if getattr(self, field) is not None:
                setattr(self, field, np.asarray(getattr(self, field), dtype=np.float64))
        self.states = np.asarray(self.states, dtype=np.float64)
        self.actions = np.asarray(self.actions, dtype=np.float64)
        if self.final_state is not None:
            self.final_state = np.asarray(self.final_state, dtype=np.float64)
        if self.rewards is not None:
            self.rewards = np.asarray(self.rewards, dtype=np.float64)
        if self.sources is None:
            self.sources = ["policy"] * len(self.states)

    def __len__(self):
        return len(self.states)

    @property
    def realistic_success(self):
        """Stacked without touching a wall: the paper's realistic success."""
        return bool(self.stacked and not self.wall_contact)

    @property
    def source(self):
        """The steps' common source, or "mixed"."""
        kinds = set(self.sources)
        return kinds.pop() if len(kinds) == 1 else "mixed"

    @property
    def observations(self):
        """The T + 1 states (Minari's `observations`: `states` then `final_state`), or None
        when the final state is unknown."""
        if self.final_state is None:
            return None
        return np.vstack([self.states, self.final_state[None, :]])

    def _as_record(self):
        return {
            "name": self.name,
            "seed": int(self.seed),
            "states": self.states,
            "actions": self.actions,
            "sources": list(self.sources),
            "origin": self.origin,
            "steps": int(self.steps),
            "dice_in_cup": int(self.dice_in_cup),
            "dice_in_cup_now": int(self.dice_in_cup_now),
            "stacked": bool(self.stacked),
            "stacked_steps": int(self.stacked_steps),
            "wall_contact": bool(self.wall_contact),
            "final_state": self.final_state,
            "rewards": self.rewards,
            "terminated": bool(self.terminated),
            "truncated": bool(self.truncated),
            **{field: getattr(self, field) for field in self._ARM_FIELDS},
        }

    @classmethod
    def _from_record(cls, record):
        return cls(**record)


def _records(episodes):
    out = []
    for e in episodes:
        if not isinstance(e, Episode):
            raise TypeError(f"expected dicestack.Episode objects, got {type(e).__name__}")
        out.append(e._as_record())
    return out


def load_demos(source="builtin", world=None):
    """Episodes of a demonstration set: "builtin" (80 expert successes, generated on first use),
    "human" (the paper's 68 recordings, converted) or a folder. `world` picks the world the
    built-in and human sets are made for (a folder carries its own)."""
    if not isinstance(source, (str, os.PathLike)):
        raise TypeError(f"source must be 'builtin', 'human' or a folder, got {type(source).__name__}")
    folder = _dicestack.resolve_demo_set(os.fspath(source), resolve_world(world))
    data = _dicestack.read_demo_set(folder)
    return [Episode._from_record(r) for r in data["episodes"]]


def save_demos(episodes, path, world=None, description="", provenance=""):
    """Writes `episodes` as a demonstration set in folder `path` (created, or replaced whole when
    it is a dicestack set; any other folder is refused with ValueError)."""
    _dicestack.write_demo_set(
        os.fspath(path),
        _records(episodes),
        resolve_world(world),
        description or "episodes saved from Python",
        provenance or "dicestack.save_demos",
    )


def view_dataset(demos, out, *, world=None):
    """Writes the episode viewer of `dicestack dataset view DEMOS --out OUT`: the page `out` (an
    .html file) lists the episodes with their outcomes and plays the chosen one beside plots of
    its states and actions; each episode's numbers go to `<stem>_files/` beside it
    (docs/results-pages.md). Returns the page's path.

    demos: "builtin", "human", a folder, or a list of dicestack.Episode (shown as
    "<episodes from Python>", drawn in `world`). `world` is the world the built-in and human sets
    are made for and the one Episodes are drawn in (None: the paper's); a folder carries its own.
    An existing page or folder is replaced only if dicestack wrote it: anything else at `out` or
    `<stem>_files` is refused with ValueError (the command line's message) and left untouched;
    a missing folder is FileNotFoundError."""
    if isinstance(demos, (str, os.PathLike)):
        source = os.fspath(demos)
    else:
        source = _records(list(demos))
    if not isinstance(out, (str, os.PathLike)):
        raise TypeError(f"out must be a path, got {type(out).__name__}")
    _dicestack.view_dataset(source, os.fspath(out), resolve_world(world))
    return os.fspath(out)
