"""Learned C-space models on disk: trained once per robot + tool + wrist + sphere radius + settings.

A model is a .npz file named by the SHA-256 of everything it was trained from (`learned.model_key`),
in `ROBOMAX_CACHE`, else `$XDG_CACHE_HOME/robomax_py`, else `~/.cache/robomax_py` (subfolder
`cspace`). A file that cannot be read, or holds another version or key, is trained again and
replaced; files are written whole (a temporary file renamed into place), so concurrent planners
never read half a model. A cache folder that cannot be written only costs the training next time.
"""

from __future__ import annotations

import zipfile
from pathlib import Path

import numpy as np

from robomax_py._typing import FloatArray
from robomax_py.cache_files import cache_folder, store_arrays
from robomax_py.cspace.learned import (
    LearnedModel,
    TrainingSettings,
    from_arrays,
    model_key,
    to_arrays,
    tool_scene,
    train,
)
from robomax_py.robot import RobotModel
from robomax_py.spec import CellSpec


def cache_dir() -> Path:
    """The folder models are kept in (not created here)."""
    return cache_folder("cspace")


def learned_model(
    cell: CellSpec, robot: RobotModel, wrist: FloatArray, radius: float,
    settings: TrainingSettings = TrainingSettings(), folder: Path | None = None,
) -> tuple[LearnedModel, bool]:
    """The model for the cell's robot and tool with this wrist and sphere radius: from the cache when
    there, else trained and stored. Returns (model, whether it came from the cache)."""
    folder = cache_dir() if folder is None else folder
    scene0 = tool_scene(cell, robot)
    key = model_key(robot, scene0, np.asarray(wrist, dtype=float), radius, settings)
    path = folder / f"{key}.npz"
    if path.is_file():
        try:
            with np.load(path, allow_pickle=False) as data:
                model = from_arrays({name: data[name] for name in data.files}, key)
        except (OSError, ValueError, zipfile.BadZipFile, EOFError):
            model = None
        if model is not None:
            return model, True
    model = train(scene0, robot, wrist, radius, settings)
    _store(path, model)
    return model, False


def _store(path: Path, model: LearnedModel) -> None:
    store_arrays(path, to_arrays(model))     # an unwritable cache: the model is trained again next time
