"""Independent client of a secured Shoal fleet, with the Python eclipse-zenoh package (1.10.2).

Plays three parties against a coordinator whose router requires mutual TLS and enforces the
access-control rules `shoal-coordinator keys` writes:

- a stranger: plain TCP to the TLS port, and TLS with the fleet CA but no certificate of its own;
  both must fail to open a session;
- a vehicle (auv1's certificate) misbehaving: it publishes auv2's telemetry, an order on auv2's
  inbox, a fleet context, an obstacle, and submits a mission;
- an operator watching every key (`shoal/**`): none of the vehicle's forgeries may reach it.
  Then the operator publishes an obstacle and queries the status, which must work.

    python secured_client.py ENDPOINT KEYS_DIR MISSION [--submit] [--obstacle-wait 60]

With --submit the coordinator is `serve`: the vehicle's submission must get no reply and the
operator's (the scenario read from --scenario) must be accepted. Prints one JSON summary line on
stdout; exit 0 when every check passed, 1 otherwise (the reasons on stderr).
"""

import argparse
import json
import os
import sys
import threading
import time

import zenoh


def config(endpoint, keys=None, member=None, ca_only=False):
    if member is not None:
        conf = zenoh.Config.from_file(os.path.join(keys, member + ".json5"))
    else:
        conf = zenoh.Config()
    if ca_only:
        conf.insert_json5(
            "transport/link/tls/root_ca_certificate",
            json.dumps(os.path.join(keys, "ca.pem")),
        )
    conf.insert_json5("mode", '"client"')
    conf.insert_json5("connect/endpoints", json.dumps([endpoint]))
    conf.insert_json5("scouting/multicast/enabled", "false")
    return conf


def cannot_open(conf):
    try:
        s = zenoh.open(conf)
    except Exception as e:  # zenoh raises ZError on a refused or failed handshake
        return True, str(e)[:200]
    s.close()
    return False, "opened"


def open_retrying(conf, seconds=30.0):
    """`run` closes its planning router before it opens the execution's: retry across the gap."""
    deadline = time.time() + seconds
    while True:
        try:
            return zenoh.open(conf)
        except Exception:
            if time.time() > deadline:
                raise
            time.sleep(0.3)


def telemetry(mission, vehicle, position, seq):
    return json.dumps({
        "version": 1, "mission": mission, "vehicle": vehicle, "seq": seq, "revision": 0,
        "sent_unix_us": int(time.time() * 1e6),
        "state": {
            "t_s": 0.0, "position": position, "velocity": [0.0, 0.0, 0.0],
            "heading_deg": 0.0, "battery": 1.0, "status": "fault",
        },
    }).encode()


def obstacle(oid, centre, radius):
    return json.dumps({
        "id": oid, "kind": "hard", "centre": centre, "radius_m": radius, "inflation_m": 0.0,
    }).encode()


def replies(session, key, payload, timeout=3.0):
    out = []
    for reply in session.get(key, payload=payload, timeout=timeout):
        if reply.ok is not None:
            out.append(json.loads(reply.ok.payload.to_bytes()))
    return out


def main() -> int:
    ap = argparse.ArgumentParser()
    ap.add_argument("endpoint")
    ap.add_argument("keys")
    ap.add_argument("mission")
    ap.add_argument("--submit", action="store_true")
    ap.add_argument("--scenario")
    ap.add_argument("--obstacle-wait", type=float, default=60.0)
    a = ap.parse_args()
    failures = []
    summary = {}

    plain = a.endpoint.replace("tls/", "tcp/", 1)
    summary["stranger_plain_tcp_refused"], why1 = cannot_open(config(plain))
    summary["stranger_tls_without_certificate_refused"], why2 = cannot_open(
        config(a.endpoint, a.keys, ca_only=True))
    if not summary["stranger_plain_tcp_refused"]:
        failures.append("a stranger opened a plain TCP session: " + why1)
    if not summary["stranger_tls_without_certificate_refused"]:
        failures.append("a stranger opened a TLS session without a certificate: " + why2)

    operator = open_retrying(config(a.endpoint, a.keys, "operator"))
    lock = threading.Lock()
    seen = []

    def keep(sample):
        with lock:
            seen.append((str(sample.key_expr), sample.payload.to_bytes()))

    watch = operator.declare_subscriber("shoal/**", keep)
    m = a.mission
    if not a.submit:
        # Wait for the execution: auv1's own telemetry reaching the operator.
        deadline = time.time() + a.obstacle_wait
        while time.time() < deadline:
            with lock:
                if any(k == f"shoal/{m}/telemetry/auv1" for k, _ in seen):
                    break
            time.sleep(0.2)
        else:
            failures.append("no telemetry of auv1 reached the operator")

    vehicle = open_retrying(config(a.endpoint, a.keys, "auv1"))
    forged = {
        f"shoal/{m}/telemetry/auv2": telemetry(m, "auv2", [1900.0, 0.0, -50.0], 2**64 - 1),
        f"shoal/{m}/vehicle/auv2/in": b"\x05\x00forged-hold",
        f"shoal/{m}/fleet": b"\x05\x00forged-context",
        f"shoal/{m}/obstacles": obstacle("forged-by-auv1", [0.0, 0.0, 0.0], 1e300),
    }
    # On its own key the router lets it through: the coordinator must see that the report
    # names another vehicle and drop it.
    own_key_for_auv2 = telemetry(m, "auv2", [1900.0, 0.0, -50.0], 7)
    for _ in range(10):
        for key, payload in forged.items():
            vehicle.put(key, payload)
        vehicle.put(f"shoal/{m}/telemetry/auv1", own_key_for_auv2)
        time.sleep(0.1)
    summary["vehicle_submit_replies"] = len(
        replies(vehicle, "shoal/submit", b'{"version":1}'))
    if summary["vehicle_submit_replies"]:
        failures.append("a vehicle's submission got a reply")
    time.sleep(1.0)
    with lock:
        leaked = sorted({k for k, p in seen if k in forged and p == forged[k]})
    summary["forgeries_delivered"] = leaked
    if leaked:
        failures.append("the vehicle's forgeries reached the operator on " + ", ".join(leaked))
    vehicle.close()

    if a.submit:
        with open(a.scenario) as f:
            text = f.read()
        sub = {"version": 1, "scenario_toml": text, "mission": m, "time_scale": 200.0,
               "iterations": 20}
        got = replies(operator, "shoal/submit", json.dumps(sub).encode(), timeout=10.0)
        summary["operator_submission"] = got
        if not (got and got[0].get("accepted")):
            failures.append(f"the operator's submission was not accepted: {got}")
    else:
        operator.put(f"shoal/{m}/obstacles", obstacle("op-1", [1950.0, 50.0, 1950.0], 5.0))
        deadline = time.time() + 10.0
        found = False
        while time.time() < deadline and not found:
            with lock:
                found = any(k == f"shoal/{m}/events" and b"op-1" in p for k, p in seen)
            time.sleep(0.2)
        summary["operator_obstacle_event"] = found
        if not found:
            failures.append("the operator's obstacle never showed up as an event")
        statuses = replies(operator, f"shoal/{m}/status", None)
        summary["operator_status_replies"] = len(statuses)
        if not statuses:
            failures.append("the operator's status query got no reply")
    watch.undeclare()
    operator.close()
    summary["failures"] = failures
    print(json.dumps(summary))
    for f in failures:
        print(f, file=sys.stderr)
    return 1 if failures else 0


if __name__ == "__main__":
    sys.exit(main())
