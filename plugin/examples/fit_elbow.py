"""The numbers of docs/howto-own-model.md: models/elbow_arm.xml as shipped, with the fit check's
series/prestretch, and with more force (parallel=3). The flexor is held at ctrl = 1 from t = 1 s,
the extensor at 0; prints the elbow angle and both tensions at t = 8 s.

Usage: .venv/bin/python plugin/examples/fit_elbow.py build/plugin/librecruit_sma.so
"""
import math
import sys

import mujoco

mujoco.mj_loadPluginLibrary(sys.argv[1] if len(sys.argv) > 1 else "build/plugin/librecruit_sma.so")
XML = open("models/elbow_arm.xml").read()


def variant(flexor, extensor):
    x = XML.replace('<config key="prestretch" value="0.012"/>', flexor)
    return x.replace('<config key="prestretch" value="0.001"/>', extensor)


CASES = {
    "as shipped": XML,
    "series=4 (fit)": variant(
        '<config key="series" value="4"/><config key="prestretch" value="0.016"/>',
        '<config key="series" value="4"/><config key="prestretch" value="0.00204"/>'),
    "series=4 parallel=3": variant(
        '<config key="series" value="4"/><config key="parallel" value="3"/>'
        '<config key="prestretch" value="0.016"/>',
        '<config key="series" value="4"/><config key="prestretch" value="0.00204"/>'),
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
