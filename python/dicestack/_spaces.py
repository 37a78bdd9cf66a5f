"""Observation and action spaces: gymnasium.spaces.Box when gymnasium is importable, otherwise
a small Box with the same fields and methods (low, high, shape, dtype, sample, contains, seed)."""
import numpy as np

try:
    import gymnasium
except ImportError:  # Debian has no gymnasium package; the fallback keeps the same contract
    gymnasium = None


class Box:
    """A box in R^n, as much of gymnasium.spaces.Box as dicestack's spaces need."""

    def __init__(self, low, high, dtype=np.float64, seed=None):
        self.dtype = np.dtype(dtype)
        self.low = np.array(low, dtype=self.dtype)
        self.high = np.array(high, dtype=self.dtype)
        if self.low.shape != self.high.shape:
            raise ValueError(f"low and high differ in shape: {self.low.shape} and {self.high.shape}")
        self.shape = self.low.shape
        self._np_random = None
        if seed is not None:
            self.seed(seed)

    @property
    def np_random(self):
        if self._np_random is None:
            self.seed()
        return self._np_random

    def seed(self, seed=None):
        self._np_random = np.random.default_rng(seed)
        return [seed]

    def sample(self):
        """Uniform where both bounds are finite, exponential off a single bound, normal otherwise
        (Gymnasium's rule)."""
        rng = self.np_random
        low_ok, high_ok = np.isfinite(self.low), np.isfinite(self.high)
        out = rng.normal(size=self.shape)
        both = low_ok & high_ok
        out[both] = rng.uniform(self.low[both], self.high[both])
        only_low, only_high = low_ok & ~high_ok, ~low_ok & high_ok
        out[only_low] = self.low[only_low] + rng.exponential(size=int(only_low.sum()))
        out[only_high] = self.high[only_high] - rng.exponential(size=int(only_high.sum()))
        return out.astype(self.dtype)

    def contains(self, x):
        x = np.asarray(x)
        return bool(
            x.shape == self.shape
            and np.can_cast(x.dtype, self.dtype)
            and np.all(x >= self.low)
            and np.all(x <= self.high)
        )

    __contains__ = contains

    def __eq__(self, other):
        return (
            isinstance(other, Box)
            and self.shape == other.shape
            and self.dtype == other.dtype
            and np.array_equal(self.low, other.low)
            and np.array_equal(self.high, other.high)
        )

    def __repr__(self):
        return f"Box({self.low.min()}, {self.high.max()}, {self.shape}, {self.dtype})"


def box(low, high):
    """A float64 Box: gymnasium's when importable."""
    if gymnasium is not None:
        return gymnasium.spaces.Box(low=np.asarray(low, np.float64), high=np.asarray(high, np.float64), dtype=np.float64)
    return Box(low, high)


def batch(low, high, n):
    """The Box of n stacked copies (a vector environment's space)."""
    return box(np.tile(low, (n, 1)), np.tile(high, (n, 1)))
