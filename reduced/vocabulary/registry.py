"""Model registries (reservoir_model, finger_model): a name -> model dict, filled on first use."""
from __future__ import annotations

import importlib

from softhand.reduced.vocabulary.errors import InputError


def lookup(models: dict, name: str, *, module: str, field: str):
    """``models[name]``; a missing name imports ``module`` once (which must register it);
    still missing: InputError naming ``field`` and the models available."""
    if name not in models:
        try:
            importlib.import_module(module)
        except ModuleNotFoundError:
            pass
    if name not in models:
        raise InputError(field, name, f"no such model; available: {', '.join(models)}")
    return models[name]
