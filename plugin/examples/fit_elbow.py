"""The numbers of docs/howto-own-model.md, "The elbow arm, before and after": models/elbow_arm.xml
with its bundles as first drafted (60 default units each, prestretch 12 mm / 1 mm), with the fit
check's series/prestretch, with more force (parallel=3), and as shipped. The flexor is held at
ctrl = 1 from t = 1 s, the extensor at 0; prints the elbow angle and both tensions at t = 8 s.
Usage: .venv/bin/python plugin/examples/fit_elbow.py build/plugin/librecruit_sma.so
"""
import math
import re
import sys

import mujoco

mujoco.mj_loadPluginLibrary(sys.argv[1] if len(sys.argv) > 1 else "build/plugin/librecruit_sma.so")
XML = open("models/elbow_arm.xml").read()


def variant(flexor, extensor):
    """The shipped model with each instance's configuration replaced by the given keys."""
    def block(name, keys):
        body = "".join('<config key="%s" value="%s"/>' % kv for kv in keys.items())
        return '<instance name="%s">%s</instance>' % (name, body)
    x = XML
    for name, keys in (("flexor_units", flexor), ("extensor_units", extensor)):
        x, n = re.subn(r'<instance name="%s">.*?</instance>' % name, block(name, keys), x,
                       flags=re.S)
        assert n == 1, name
    return x


FIT_EXTENSOR = {"units": 60, "series": 4, "prestretch": 0.00204}
CASES = {
    "first draft": variant({"units": 60, "prestretch": 0.012}, {"units": 60, "prestretch": 0.001}),
    "series=4 (fit)": variant({"units": 60, "series": 4, "prestretch": 0.016}, FIT_EXTENSOR),
    "series=4 parallel=3": variant(
        {"units": 60, "series": 4, "parallel": 3, "prestretch": 0.016}, FIT_EXTENSOR),
    "as shipped": XML,
}
for name, xml in CASES.items():
    m = mujoco.MjModel.from_xml_string(xml)
    d = mujoco.MjData(m)
    flexor = mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_ACTUATOR, "flexor")
    extensor = mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_ACTUATOR, "extensor")
    peak = 0.0
    while d.time < 8.0 - 1e-9:
        d.ctrl[flexor] = 1.0 if d.time >= 1.0 else 0.0
        mujoco.mj_step(m, d)
        peak = max(peak, d.qpos[0])
    mujoco.mj_forward(m, d)
    print("%-22s elbow at 8 s %.1f deg (max %.1f), flexor %.2f N, extensor %.2f N" %
          (name, math.degrees(d.qpos[0]), math.degrees(peak), -d.actuator_force[flexor],
           -d.actuator_force[extensor]))
