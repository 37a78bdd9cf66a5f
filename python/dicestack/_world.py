"""Worlds as the package takes them: None (the paper's world), a path to a `dicestack config`
JSON file, a dict in that format, or a WorldConfig."""
import json
import os

from . import _dicestack


def resolve_world(world=None):
    """The _dicestack.WorldConfig for `world`; ValueError names a bad field, FileNotFoundError a
    missing file."""
    if world is None:
        return _dicestack.WorldConfig()
    if isinstance(world, _dicestack.WorldConfig):
        return world
    if isinstance(world, dict):
        try:
            text = json.dumps(world, allow_nan=False)
        except (TypeError, ValueError) as e:
            raise ValueError(f"world config <dict>: not JSON: {e}") from None
        return _dicestack.WorldConfig.from_json(text, "<dict>")
    if isinstance(world, (str, os.PathLike)):
        return _dicestack.WorldConfig.load(os.fspath(world))
    raise TypeError(f"world must be None, a path, a dict or a WorldConfig, got {type(world).__name__}")


def default_world():
    """The paper's world as a dict in `dicestack config`'s format: edit it and pass it as `world`."""
    return json.loads(_dicestack.WorldConfig().to_json())


def world_dict(config):
    """A WorldConfig as a dict."""
    return json.loads(config.to_json())
