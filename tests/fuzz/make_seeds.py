#!/usr/bin/env python3
"""Writes the seed corpus (corpus/<target>/seed_*): the repository's task, model and log files
plus hand-made edge cases. Run from anywhere; files found by fuzzing are added beside them as
crash-* / regress-* and are not touched here."""
import pathlib

HERE = pathlib.Path(__file__).resolve().parent
ROOT = HERE.parents[1]
CORPUS = HERE / "corpus"


def write(target, name, data):
    d = CORPUS / target
    d.mkdir(parents=True, exist_ok=True)
    (d / ("seed_" + name)).write_bytes(data if isinstance(data, bytes) else data.encode())


# --- task (the task file lives in models/tasks, so "../elbow_arm.xml" resolves) ---
for p in sorted((ROOT / "models/tasks").glob("*.json")):
    write("task", p.name, p.read_bytes())
for p in [ROOT / "tests/sim/data/bad_lambda.json", ROOT / "tests/render/data/bench_task.json"]:
    write("task", p.name, p.read_bytes().replace(b"../../../models/", b"../"))
base = ('{"name": "t", "model": "../isometric_bench.xml", "tracked": "force", "agonist": "bundle", '
        '"duration": 5, "reference": %s}')
write("task", "ramp.json", base % '{"type": "ramp", "start": 1, "end": 3, "from": 0, "to": 10}')
write("task", "piecewise.json", base % '{"type": "piecewise", "points": [[0, 0], [1, 5], [1, 2]]}')
write("task", "fig5.json", base % '{"type": "paper_fig5"}')
write("task", "huge_number.json", base % '{"type": "constant", "value": 1e999}')
write("task", "name_escape.json", (base % '{"type": "constant", "value": 3}').replace('"t"', '"../escaped"'))
write("task", "bom.json", b"\xef\xbb\xbf" + (base % '{"type": "constant", "value": 3}').encode())
write("task", "deep.json", "[" * 200 + "]" * 200)
write("task", "not_object.json", "[1, 2, 3]")
write("task", "empty.json", "")
write("task", "payloads.json", (base % '{"type": "constant", "value": 3}')[:-1] +
      ', "payloads": [{"body": "b", "mass": 0.1, "time": 1}], "timestep": 0.001, '
      '"sensor": {"noise_std": 0.1, "resolution": 0.01, "seed": 3}, "settle_band": 0.05}')

# --- filter_model ---
write("filter_model", "three_state.json", (ROOT / "models/filter/three_state_model.json").read_bytes())
write("filter_model", "identified_m20.json",
      (ROOT / "models/identified/bench_n60_dt2.0_m20.json").read_bytes())
two = ('{"states": ["off", "on"], "N": %s, "H": [[0, 0.45]], "R": [[0.01]], '
       '"transition": {"type": "broadcast", "dt": 2, "is_on": [false, true], '
       '"on_target": 1, "off_target": 0}}')
write("filter_model", "two_state.json", two % "60")
write("filter_model", "huge_n.json", two % "9223372036854775807")
write("filter_model", "explicit.json",
      '{"states": ["a", "b"], "N": 5, "H": [[1, 0], [0, 1]], "R": [[1, 0], [0, 1]], '
      '"transition": {"type": "explicit"}, "initial": {"x0": [2.5, 2.5], "P0": [[1, -1], [-1, 1]]}}')
write("filter_model", "constant_noise.json",
      '{"states": ["a", "b"], "N": 4, "H": [[1, 2]], "R": [[0.5]], "G": [[1], [-1]], "Qw": [[0.1]], '
      '"transition": {"type": "constant", "A": [[0.5, 0.5], [0.5, 0.5]]}}')
write("filter_model", "bad_r.json", (two % "60").replace("0.01", "-1"))
write("filter_model", "number_too_large.json", (two % "60").replace("0.01", "1e999"))

# --- filter_log: byte 0 = model (0 broadcast, 1 explicit, 2 constant), byte 1 = estimator
# (0 extended, 1 conservative, 2 plain, 3 exact, 4 particle) ---
three_log = (ROOT / "models/filter/three_state_log.csv").read_bytes()
for est in range(5):
    write("filter_log", "broadcast_%d.csv" % est, bytes([0, est]) + three_log)
write("filter_log", "broadcast_bom.csv", b"\x00\x00\xef\xbb\xbf" + three_log)
write("filter_log", "broadcast_gaps.csv",
      b"\x00\x00# comment\nt,p_on,p_off,y\n0,0.2,0,\n\n0.5,0.2,0,1.5\n1,,,\n")
write("filter_log", "broadcast_bad.csv", b"\x00\x00p_off,y,p_on\n0,nan,1\n1,+1e400,0\n")
explicit_log = (b"t,A_0_0,A_1_0,A_0_1,A_1_1,y_0,y_1\n"
                b"0,0.9,0.1,0.2,0.8,4,2\n1,1,0,0,1,,\n2,0.5,0.5,0.5,0.5,3.1,2.9\n3,,,,,3,3\n")
for est in range(5):
    write("filter_log", "explicit_%d.csv" % est, bytes([1, est]) + explicit_log)
write("filter_log", "explicit_not_stochastic.csv", b"\x01\x00A_0_0,A_1_0,A_0_1,A_1_1,y_0,y_1\n"
      b"0.9,0.2,0.2,0.8,4,2\n")
write("filter_log", "constant.csv", b"\x02\x00y\n15\n17.5\n\n18\n")
write("filter_log", "constant_t_only.csv", b"\x02\x01t\n0\n1\n")
write("filter_log", "header_only.csv", b"\x00\x00t,p_on,p_off,y\n")
write("filter_log", "empty.csv", b"\x00\x00")

# --- bundle_config: byte 0 even = FromText "key=value ...", odd = one value per line in
# Keys() order (law, units, wire_diameter, ...); byte 1 = timestep (1e-4, 2e-3, 0.05) ---
write("bundle_config", "default.txt", b"\x00\x01")
write("bundle_config", "bench.txt", b"\x00\x01units=60 law=spring series=2 parallel=1 update_period=0.004")
write("bundle_config", "wire.txt", b"\x00\x00law=wire prestrain=0.03 merge_temperature=0 merge_xi=0")
write("bundle_config", "many_units.txt", b"\x00\x02units=1000000")
write("bundle_config", "bad.txt", b"\x00\x01units=1e999 wire_length=-1 law=bogus")
write("bundle_config", "twice.txt", b"\x00\x01units=3 units=4")
write("bundle_config", "no_equals.txt", b"\x00\x01units")
write("bundle_config", "lines.txt", b"\x01\x01spring\n60\n\n\n\n\n2\n")
write("bundle_config", "lines_wire.txt", b"\x01\x02wire\n5\n0.0001\n0.1\n")
write("bundle_config", "lines_nan.txt", b"\x01\x01\nnan\ninf\n-0\n0x10\n 5\n")

# --- mjcf_config: one value per line for law, units, ... (the 35 BundleConfig keys), then seed
# and broadcast_period ---
def lines(values):
    out = [""] * 37
    for i, v in values.items():
        out[i] = v
    return "\n".join(out).rstrip("\n")


write("mjcf_config", "bench.txt", lines({1: "60"}))
write("mjcf_config", "wire.txt", lines({0: "wire", 1: "12", 9: "0.03", 35: "7", 36: "0.01"}))
write("mjcf_config", "spring_period.txt", lines({0: "spring", 1: "30", 34: "0.004", 36: "0.5"}))
write("mjcf_config", "bad_seed.txt", lines({35: "-3"}))
write("mjcf_config", "bad_period.txt", lines({36: "soon"}))
write("mjcf_config", "huge_seed.txt", lines({35: "18446744073709551616"}))
write("mjcf_config", "xml_chars.txt", lines({0: "<&\"'>", 1: "6\x01"}))
write("mjcf_config", "many_units.txt", lines({1: "100000"}))


# --- sil_packet: frames of docs/sil.md (byte 0 also sets the stream's piece size) ---
import struct


def crc16(data):
    c = 0xFFFF
    for x in data:
        c ^= x << 8
        for _ in range(8):
            c = ((c << 1) ^ 0x1021) & 0xFFFF if c & 0x8000 else (c << 1) & 0xFFFF
    return c


def frame(kind, n, seq, values):
    body = bytes([0x5A, ord(kind), n]) + struct.pack("<I", seq) + struct.pack("<%dd" % len(values), *values)
    return body + struct.pack("<H", crc16(body))


hello = frame("H", 2, 0, [1.0])
meas = frame("M", 2, 7, [7.0, 0.5, 0.4, -0.01, 3.2, 2.9, 0.031, 0.029])
cmd = frame("C", 2, 7, [3.0, 0.2, 0.0, 11.5, 0.8, 1.0, 0.0, 0.05, 2.0, float("nan")])
end = frame("E", 1, 40, [])
write("sil_packet", "hello", hello)
write("sil_packet", "measurement", meas)
write("sil_packet", "command", cmd)
write("sil_packet", "end", end)
write("sil_packet", "bad_crc", cmd[:-1] + bytes([cmd[-1] ^ 1]))
write("sil_packet", "truncated", cmd[:-3])
write("sil_packet", "p_above_one", frame("C", 1, 3, [1.0, 1.5, 0.0, 1.0, 0.1]))
write("sil_packet", "eight_bundles", frame("C", 8, 9, [0.5] * 40))
write("sil_packet", "stream", bytes([0x5A, 0x13]) + hello + meas + b"\x5a\x43" + cmd + cmd[:10] + end)
