"""Hostile submissions to `shoal-coordinator serve`, sent by an independent client (the Python
eclipse-zenoh package, 1.10.2) as a stranger on the network would.

    python hostile_submissions.py ENDPOINT DATA_DIR SCENARIO.toml [--scenario-limits]
                                  [--write DIR]

Builds the corpus (about 70 submissions: malformed envelopes, out-of-range numbers, files
outside the data directory, path-like mission ids, a duplicate id, a flood), prepares DATA_DIR
(a good current grid, a symbolic link to /etc/passwd, a FIFO, an oversized sparse file), sends
each submission on `shoal/submit` and checks its receipt against what the case expects.
`--scenario-limits` adds the cases that only scenario validation refuses (10^6 waypoints, 500
vehicles, ...). `--write DIR` also writes each submission to DIR/<case>.json.

Prints one JSON summary line on stdout; exit 0 when every case got what it expects and no reply
contains "root:" (the first line of /etc/passwd), 1 otherwise (the reasons on stderr).
"""

import argparse
import json
import os
import sys

import zenoh

# The one message a client gets for any file it may not use (missing, outside, not regular).
OUTSIDE = "names a file outside the data directory"
# What /etc/passwd starts with: no reply may ever contain it.
LEAK = "root:"


def case(name, payload, expect, says=None):
    """One submission: `expect` is "accept" or "refuse"; `says` a text the error must contain."""
    if not isinstance(payload, bytes):
        payload = json.dumps(payload).encode()
    return {"name": name, "payload": payload, "expect": expect, "says": says}


def sub(scenario, **fields):
    """A submission of `scenario` with `fields`; fast by default (it may be run)."""
    s = {"version": 1, "scenario_toml": scenario, "iterations": 1, "time_scale": 10000.0,
         "in_process": True}
    s.update(fields)
    return s


def with_line(scenario, old, new):
    """`scenario` with the line starting `old` replaced by `new`."""
    lines = [new if line.startswith(old) else line for line in scenario.splitlines()]
    assert lines != scenario.splitlines(), old
    return "\n".join(lines) + "\n"


def envelope_cases(base):
    ok = sub(base, mission="env")
    return [
        case("empty", b"", "refuse", "not a submission"),
        case("not-json", b"this is not json", "refuse", "not a submission"),
        case("invalid-utf8", b"\xff\xfe\xfd", "refuse", "not a submission"),
        case("json-array", b"[]", "refuse", "not a submission"),
        case("json-null", b"null", "refuse", "not a submission"),
        case("trailing-bytes", json.dumps(ok).encode() + b" x", "refuse", "not a submission"),
        case("nested-10e5", b"[" * 100_000 + b"]" * 100_000, "refuse", "not a submission"),
        case("version-0", dict(ok, version=0), "refuse", "version 0"),
        case("version-overflow", dict(ok, version=65536), "refuse", "not a submission"),
        case("version-negative", dict(ok, version=-1), "refuse", "not a submission"),
        case("no-scenario", {"version": 1}, "refuse", "not a submission"),
        case("unknown-field", dict(ok, admin=True), "refuse", "not a submission"),
        case("scenario-number", dict(ok, scenario_toml=7), "refuse", "not a submission"),
        case("oversized-2MB", dict(ok, scenario_toml=base + "#" * (2 << 20)), "refuse",
             "over the limit 1048576"),
        case("scenario-empty", dict(ok, scenario_toml=""), "refuse", "<submitted scenario>"),
        case("scenario-binary", dict(ok, scenario_toml="\u0000\u0001\ufffd" * 100), "refuse",
             "<submitted scenario>"),
        case("in-process-string", dict(ok, in_process="yes"), "refuse", "not a submission"),
        case("seed-negative", dict(ok, seed=-1), "refuse", "not a submission"),
    ]


def number_cases(base):
    return [
        case("iterations-1e12", sub(base, iterations=10**12), "refuse",
             "iterations = 1000000000000 is over the limit 1000000"),
        case("iterations-2^64", b'{"version":1,"scenario_toml":"","iterations":18446744073709551616}',
             "refuse", "not a submission"),
        case("iterations-negative", sub(base, iterations=-1), "refuse", "not a submission"),
        case("iterations-fraction", sub(base, iterations=1.5), "refuse", "not a submission"),
        case("iterations-times-particles", sub(with_line(base, "particles", "particles = 5000"),
                                                iterations=1_000_000), "refuse",
             "particles × populations × iterations × vehicles"),
        case("scenario-particles-1e9", sub(with_line(base, "particles", "particles = 1000000000"),
                                           iterations=None), "refuse", "particles"),
        case("scenario-populations-1e9", sub(with_line(base, "populations", "populations = 1000000000"),
                                             iterations=None), "refuse", "populations"),
        case("scenario-iterations-1e12", sub(with_line(base, "iterations", "iterations = 1000000000000"),
                                             iterations=None), "refuse", "iterations"),
        case("time-scale-1e-6", sub(base, time_scale=1e-6), "refuse", "time_scale = 0.000001"),
        case("time-scale-zero", sub(base, time_scale=0.0), "refuse", "time_scale = 0"),
        case("time-scale-negative", sub(base, time_scale=-5.0), "refuse", "time_scale = -5"),
        case("time-scale-1e308", sub(base, time_scale=1e308), "refuse", "time_scale"),
        case("time-scale-slow", sub(base, time_scale=0.1), "refuse", "--max-mission-hours"),
        case("telemetry-1e6", sub(base, telemetry_hz=1e6), "refuse", "telemetry_hz = 1000000"),
        case("telemetry-zero", sub(base, telemetry_hz=0.0), "refuse", "telemetry_hz = 0"),
    ]


def scenario_limit_cases(base):
    """Refused by scenario validation (its limits), not by `serve`'s own checks."""
    # As many one-metre obstacles as fit in a submission (10^4 took replans to 3 to 6 s).
    many = base + "".join(
        f'[[obstacles]]\nid="o{i}"\nkind="hard"\ncentre=[0,0,-100]\nradius_m=1\ninflation_m=1\n'
        for i in range(10_500))
    vehicles = base + "".join(
        f'\n[[vehicles]]\nid = "x{i}"\nkind = "auv"\nstart = [0.0, {i}.0, -100.0]\n'
        f"goal = [100.0, {i}.0, -100.0]\nspeed_min_mps = 1.0\nspeed_max_mps = 2.0\n"
        f"max_turn_deg = 35.0\nmax_pitch_deg = 20.0\n" for i in range(500))
    return [
        case("scenario-waypoints-1e6", sub(with_line(base, "waypoints", "waypoints = 1000000")),
             "refuse", "waypoints"),
        case("scenario-obstacles-10500", sub(many), "refuse", "obstacles"),
        case("scenario-vehicles-500", sub(vehicles), "refuse", "vehicles"),
    ]


def prepare_data_dir(data):
    """A good grid, a link out, a FIFO, an oversized sparse file and a directory."""
    with open(os.path.join(data, "uniform.csv"), "w", encoding="utf-8") as f:
        f.write("x,y,z,u,v,w\n1,2,3,0.5,-0.5,0\n")
    os.symlink("/etc/passwd", os.path.join(data, "link.csv"))
    os.mkfifo(os.path.join(data, "fifo.csv"))
    with open(os.path.join(data, "big.csv"), "wb") as f:
        f.truncate(65 << 20)
    os.mkdir(os.path.join(data, "sub"))


def file_cases(base):
    def currents(path):
        return sub(base + f'\n[currents]\nmodel = "grid"\nfile = {json.dumps(path)}\n')

    def seabed(path):
        return sub(base + f"\n[seabed.grid]\nfile = {json.dumps(path)}\ncell_m = 10.0\n")

    hidden = [("etc-passwd", "/etc/passwd"), ("dev-zero", "/dev/zero"),
              ("dot-dot", "../../../../../../etc/passwd"), ("missing", "/nonexistent/x.csv"),
              ("missing-inside", "none.csv"), ("proc-environ", "/proc/self/environ"),
              ("link-out", "link.csv"), ("fifo", "fifo.csv"), ("directory", "sub"),
              ("home", os.path.expanduser("~/.bashrc"))]
    cases = [case(f"currents-{n}", currents(p), "refuse", OUTSIDE) for n, p in hidden]
    cases += [
        case("seabed-etc-passwd", seabed("/etc/passwd"), "refuse", OUTSIDE),
        case("heightmap-etc-shadow", sub(base + '\n[coverage]\nheightmap = "/etc/shadow"\n'),
             "refuse", OUTSIDE),
        case("currents-too-large", currents("big.csv"), "refuse", "over the limit"),
        case("currents-not-a-string", sub(base + '\n[currents]\nmodel = "grid"\nfile = 3\n'),
             "refuse", "currents"),
        case("currents-inside", dict(currents("uniform.csv"), mission="data-ok"), "accept"),
    ]
    return cases


def id_cases(base):
    bad = ["..", ".", "../../tmp/x", "a/b", "", ".hidden", "x" * 65, "a\\b", "*", "a b"]
    return [case(f"mission-{i}", sub(base, mission=m), "refuse", "mission id") for i, m in enumerate(bad)]


def queue_cases(base):
    cases = [
        case("valid", sub(base, mission="ok-1"), "accept"),
        case("duplicate", sub(base, mission="ok-1"), "refuse", "already taken"),
    ]
    # Ten more than the queue needs to fill: at most 8 wait and one runs, so some are refused.
    cases += [case(f"flood-{i}", sub(base, mission=f"flood-{i}"), "flood") for i in range(10)]
    return cases


def corpus(base, scenario_limits):
    cases = envelope_cases(base) + number_cases(base) + file_cases(base) + id_cases(base)
    if scenario_limits:
        cases += scenario_limit_cases(base)
    return cases + queue_cases(base)


def check(c, raw, problems):
    """Compares one reply with the case's expectation; the receipt (or None)."""
    if raw is None:
        problems.append(f"{c['name']}: no reply")
        return None
    if LEAK.encode() in raw:
        problems.append(f"{c['name']}: the reply contains {LEAK!r}: {raw[:200]!r}")
    try:
        r = json.loads(raw)
    except ValueError:
        problems.append(f"{c['name']}: the reply is not JSON: {raw[:200]!r}")
        return None
    error = r.get("error") or ""
    if c["expect"] == "accept" and not r.get("accepted"):
        problems.append(f"{c['name']}: refused: {error}")
    if c["expect"] == "refuse":
        if r.get("accepted") is not False:
            problems.append(f"{c['name']}: accepted as {r.get('mission')}")
        elif c["says"] and c["says"] not in error:
            problems.append(f"{c['name']}: the error does not say {c['says']!r}: {error}")
    if c["expect"] == "flood" and not r.get("accepted") and not error.startswith("queue full: 8 missions waiting"):
        problems.append(f"{c['name']}: refused, not for a full queue: {error}")
    return r


def main() -> int:
    ap = argparse.ArgumentParser()
    ap.add_argument("endpoint")
    ap.add_argument("data_dir")
    ap.add_argument("scenario")
    ap.add_argument("--scenario-limits", action="store_true")
    ap.add_argument("--write")
    a = ap.parse_args()
    with open(a.scenario, encoding="utf-8") as f:
        base = f.read()
    prepare_data_dir(a.data_dir)
    cases = corpus(base, a.scenario_limits)
    if a.write:
        os.makedirs(a.write, exist_ok=True)
        for c in cases:
            with open(os.path.join(a.write, c["name"] + ".json"), "wb") as f:
                f.write(c["payload"])

    conf = zenoh.Config()
    conf.insert_json5("mode", '"client"')
    conf.insert_json5("connect/endpoints", json.dumps([a.endpoint]))
    conf.insert_json5("scouting/multicast/enabled", "false")
    session = zenoh.open(conf)

    problems, accepted, refused, queue_full, missing_files = [], [], 0, 0, []
    for c in cases:
        raw = None
        for reply in session.get("shoal/submit", payload=c["payload"], timeout=20.0):
            if reply.ok is not None:
                raw = reply.ok.payload.to_bytes()
        r = check(c, raw, problems)
        if r is None:
            continue
        if r.get("accepted"):
            accepted.append(r.get("mission"))
        else:
            refused += 1
            queue_full += (r.get("error") or "").startswith("queue full")
            if OUTSIDE in (r.get("error") or ""):
                missing_files.append(r["error"].split(": ", 2)[-1])
        print(f"{c['name']}: {'accepted' if r.get('accepted') else r.get('error')}", file=sys.stderr)
    # Missing, outside and unreadable files all read the same: nothing tells which exist.
    if len(set(missing_files)) > 1:
        problems.append(f"file refusals differ: {sorted(set(missing_files))}")
    if queue_full == 0:
        problems.append("the flood never filled the queue")
    session.close()
    print(json.dumps({"n": len(cases), "accepted": accepted, "refused": refused,
                      "queue_full": queue_full, "problems": problems}))
    for p in problems:
        print(p, file=sys.stderr)
    return 1 if problems else 0


if __name__ == "__main__":
    sys.exit(main())
