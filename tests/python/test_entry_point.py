"""`import mujoco` alone registers recruit.sma through the `mujoco.plugins` entry point.

The default test installs what `pip install .` installs for the entry point, without compiling:
the package metadata made by the real build backend from pyproject.toml (scikit-build-core's
prepare_metadata_for_build_wheel: entry_points.txt, no CMake build), the recruit_plugin module
and the built librecruit_sma.so at recruit/librecruit_sma.so, in a temporary directory on a
child interpreter's path. A full `pip install .` into a fresh venv compiles the extension
(minutes on two cores): it runs when RECRUIT_PIP_INSTALL_TEST=1.
"""
import os
import pathlib
import shutil
import subprocess
import sys
import textwrap
import venv

import pytest

import recruit

from conftest import ROOT

BENCH = str(ROOT / "models" / "isometric_bench.xml")

# Opens a bundle model with the official bindings only, runs 3 s with every unit switched on
# and prints the plugin sensor's on count; fails if recruit's package was imported.
CHILD = textwrap.dedent(f"""
    import sys, warnings
    warnings.simplefilter("error")  # a failed entry point is a RuntimeWarning in mujoco
    import mujoco
    m = mujoco.MjModel.from_xml_path({BENCH!r})
    d = mujoco.MjData(m)
    d.ctrl[0] = 1.0
    while d.time < 3:
        mujoco.mj_step(m, d)
    assert "recruit" not in sys.modules, "the recruit package was imported"
    print(int(d.sensor("bundle_truth").data[0]))
""")


def _metadata(dest):
    """The dist-info the build backend writes for this pyproject.toml (no compilation)."""
    pytest.importorskip("scikit_build_core")
    code = ("import sys, scikit_build_core.build as b; "
            "print(b.prepare_metadata_for_build_wheel(sys.argv[1]))")
    out = subprocess.run([sys.executable, "-c", code, str(dest)], cwd=ROOT, check=True,
                         capture_output=True, text=True).stdout
    return dest / out.strip().splitlines()[-1]


def _site(tmp_path, with_metadata):
    """A site directory laid out like the installed wheel, recruit's __init__ replaced by a trap."""
    site = tmp_path / "site"
    shutil.copytree(ROOT / "python" / "recruit_plugin", site / "recruit_plugin")
    (site / "recruit").mkdir()
    shutil.copy(recruit.PLUGIN_LIBRARY, site / "recruit" / "librecruit_sma.so")
    (site / "recruit" / "__init__.py").write_text("raise ImportError('recruit imported')\n")
    if with_metadata:
        info = _metadata(tmp_path / "meta")
        shutil.copytree(info, site / info.name)
    return site


def _run_child(site, python=sys.executable):
    env = dict(os.environ, PYTHONPATH=str(site))
    env.pop("RECRUIT_PYTHONPATH", None)
    return subprocess.run([python, "-c", CHILD], env=env, capture_output=True, text=True,
                          cwd=site)


def test_metadata_declares_the_entry_point(tmp_path):
    info = _metadata(tmp_path)
    text = (info / "entry_points.txt").read_text()
    assert "[mujoco.plugins]" in text
    assert "recruit = recruit_plugin:load" in text
    # The wheel's version is the CMake project version.
    assert info.name == f"recruit-{recruit.__version__}.dist-info"


def test_import_mujoco_alone_loads_bundle_models(tmp_path):
    r = _run_child(_site(tmp_path, with_metadata=True))
    assert r.returncode == 0, r.stderr
    assert r.stdout.strip() == "60"  # p_on = 1 at every step: every unit on


def test_without_the_entry_point_the_model_does_not_load(tmp_path):
    # The control: the same files without the metadata, so the plugin is not registered.
    r = _run_child(_site(tmp_path, with_metadata=False))
    assert r.returncode != 0
    assert "recruit.sma" in r.stderr


def test_load_is_idempotent_and_import_recruit_after_it_works(tmp_path):
    site = _site(tmp_path, with_metadata=True)
    (site / "recruit" / "__init__.py").unlink()
    # The real package: the extension from the build tree, the shipped library beside it.
    build_pkg = pathlib.Path(recruit.__file__).parent
    for f in build_pkg.iterdir():
        if f.is_file():
            shutil.copy(f, site / "recruit" / f.name)
    code = textwrap.dedent("""
        import mujoco, recruit_plugin, recruit
        first = recruit_plugin.load()
        assert recruit_plugin.load() == first
        assert first == recruit.PLUGIN_LIBRARY, (first, recruit.PLUGIN_LIBRARY)
        with open("/proc/self/maps") as f:
            libs = {l.split()[-1] for l in f if "librecruit_sma" in l}
        assert len(libs) == 1, libs
        print("ok")
    """)
    env = dict(os.environ, PYTHONPATH=str(site))
    env.pop("RECRUIT_PYTHONPATH", None)
    r = subprocess.run([sys.executable, "-c", code], env=env, capture_output=True, text=True,
                       cwd=site)
    assert r.returncode == 0, r.stderr
    assert r.stdout.strip() == "ok"


@pytest.mark.skipif(os.environ.get("RECRUIT_PIP_INSTALL_TEST") != "1",
                    reason="compiles the package: set RECRUIT_PIP_INSTALL_TEST=1")
def test_pip_install_into_a_fresh_venv(tmp_path):
    env_dir = tmp_path / "venv"
    venv.create(env_dir, with_pip=True)  # no system site-packages
    pip = [str(env_dir / "bin" / "python"), "-m", "pip", "install", "-q",
           "--disable-pip-version-check"]
    subprocess.run(pip + ["mujoco==4.0.0"], check=True)
    subprocess.run(pip + [str(ROOT)], check=True, cwd=tmp_path)
    r = _run_child(tmp_path, python=str(env_dir / "bin" / "python"))
    assert r.returncode == 0, r.stderr
    assert r.stdout.strip() == "60"
