"""Worlds as the package takes them: None (the paper's world), a path to a `dicestack config`
JSON file, a dict in that format, or a WorldConfig."""
import json
import os

from . import _dicestack


def resolve_world(world=None, start="random", embodiment=None):
    """The _dicestack.WorldConfig for `world`, its episodes starting from `start`: "random" (the
    world's randomization) or "paper" (the paper's start at rest, the whole scene shifted in x by
    U(-2 cm, 2 cm) per episode); `embodiment` "cup" or "arm" (docs/arm.md) replaces the world's
    (None: keep it). ValueError names a bad field, start or embodiment, FileNotFoundError a
    missing file."""
    if not isinstance(start, str):
        raise TypeError(f"start must be 'random' or 'paper', got {type(start).__name__}")
    config = _resolve_config(world)
    if embodiment is not None:
        if embodiment not in ("cup", "arm"):
            shown = repr(embodiment)
            raise ValueError(f"embodiment must be 'cup' or 'arm', got {shown if len(shown) <= 40 else shown[:40] + '...'}")
        fields = json.loads(config.to_json())
        fields["embodiment"] = embodiment
        config = _dicestack.WorldConfig.from_json(json.dumps(fields), "<embodiment>")
    return config.with_starts(start)


def _resolve_config(world):
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


def resolve_perturbation(perturb, world):
    """The _dicestack.Perturbation for `perturb`: None or "none" (the nominal world), a level
    ("easy", "medium", "hard"), a path to a perturbation file, or a dict in that file's format
    (the "format" and "version" keys may be left out). ValueError names a bad field."""
    if perturb is None:
        return _dicestack.Perturbation()
    if isinstance(perturb, _dicestack.Perturbation):
        return perturb
    if isinstance(perturb, dict):
        fields = {"format": "dicestack-perturbation", "version": 2, **perturb}
        for key, value in fields.items():
            if not isinstance(key, str):
                raise ValueError(f"perturbation <dict>: a field name must be a string, got {type(key).__name__}")
            try:
                json.dumps(value, allow_nan=False)
            except (TypeError, ValueError):
                shown = repr(value)
                shown = shown if len(shown) <= 40 else shown[:40] + "..."
                raise ValueError(f'perturbation <dict>: field "{key[:40]}" must be a finite number, a boolean or '
                                 f"a string, got {shown}") from None
        text = json.dumps(fields, allow_nan=False)
        return _dicestack.Perturbation.from_json(text, "perturbation <dict>", world)
    if isinstance(perturb, (str, os.PathLike)):
        return _dicestack.Perturbation.load(os.fspath(perturb), world)
    raise TypeError(f"perturb must be None, a level, a path, a dict or a Perturbation, got {type(perturb).__name__}")


def perturbation_name(perturb):
    """How reports name `perturb`: its level or file, "<dict>", or "none"."""
    if perturb is None:
        return "none"
    if isinstance(perturb, (str, os.PathLike)):
        return os.fspath(perturb)
    return "<dict>" if isinstance(perturb, dict) else "<Perturbation>"


def default_world():
    """The paper's world as a dict in `dicestack config`'s format: edit it and pass it as `world`."""
    return json.loads(_dicestack.WorldConfig().to_json())


def world_dict(config):
    """A WorldConfig as a dict."""
    return json.loads(config.to_json())
