"""Registers the MuJoCo engine plugin ``recruit.sma`` when ``mujoco`` is imported.

``pip install .`` declares ``load`` in MuJoCo's entry point group ``mujoco.plugins``; at the end
of ``import mujoco`` the bindings call every entry point of that group, so a model declaring
``recruit.sma`` bundles opens with ``import mujoco`` alone (docs/python.md).

This is a top-level module on purpose: an entry point inside the ``recruit`` package would
import ``recruit/__init__.py`` (the extension, NumPy, and ``import mujoco`` while mujoco is still
being imported). Here only the standard library runs until ``load`` is called, and ``load``
finds the packaged ``recruit/librecruit_sma.so`` without importing ``recruit``.
"""

import importlib.util as _util
import os as _os

LIBRARY_NAME = "librecruit_sma.so"

_loaded = None  # path of the library this module registered, once loaded


def library_path():
    """The installed ``recruit/librecruit_sma.so``, or None when ``recruit`` has none."""
    spec = _util.find_spec("recruit")  # locates the package without importing it
    for folder in (spec.submodule_search_locations or []) if spec else []:
        path = _os.path.join(folder, LIBRARY_NAME)
        if _os.path.isfile(path):
            return path
    return None


def load():
    """Loads the plugin library with ``mujoco.mj_loadPluginLibrary`` once; returns its path.

    Idempotent: later calls (and ``import recruit``, which opens the same file) register nothing
    twice, as the dynamic loader returns the already loaded library.
    """
    global _loaded
    if _loaded is not None:
        return _loaded
    path = library_path()
    if path is None:
        raise ImportError(f"recruit_plugin: no {LIBRARY_NAME} in the installed recruit package")
    # Called from inside `import mujoco`, this gets the module being initialised: its functions
    # are bound by then (the entry points run last). Called first, it imports mujoco, which
    # calls load() again through the entry point; _loaded then stops the outer call.
    import mujoco

    if _loaded is None:
        mujoco.mj_loadPluginLibrary(path)
        _loaded = path
    return _loaded
