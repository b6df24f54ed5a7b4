"""Independent client of Shoal's open interface, with the Python eclipse-zenoh package (1.10.2).

Submits a scenario on `shoal/submit`, then reads back the plan, the telemetry, the live fleet
status (a query) and the events of the mission from their JSON keys, with no Rust involved.

    python submit_and_watch.py ENDPOINT SCENARIO.toml [--time-scale 100] [--iterations 40]

Prints one JSON summary line on stdout; exit 0 when every check passed, 1 otherwise (the reason
on stderr).
"""

import argparse
import json
import sys
import threading
import time

import zenoh


def main() -> int:
    ap = argparse.ArgumentParser()
    ap.add_argument("endpoint")
    ap.add_argument("scenario")
    ap.add_argument("--time-scale", type=float, default=100.0)
    ap.add_argument("--iterations", type=int, default=40)
    ap.add_argument("--timeout", type=float, default=200.0)
    a = ap.parse_args()

    conf = zenoh.Config()
    conf.insert_json5("mode", '"client"')
    conf.insert_json5("connect/endpoints", json.dumps([a.endpoint]))
    conf.insert_json5("scouting/multicast/enabled", "false")
    session = zenoh.open(conf)

    lock = threading.Lock()
    plans, telemetry, events = [], [], []

    def keep(store):
        def cb(sample):
            try:
                value = json.loads(sample.payload.to_bytes())
            except ValueError:
                return
            with lock:
                store.append((str(sample.key_expr), value))
        return cb

    # Subscribe first: the plan is published once, when the execution starts.
    subs = [
        session.declare_subscriber("shoal/*/plan", keep(plans)),
        session.declare_subscriber("shoal/*/telemetry/*", keep(telemetry)),
        session.declare_subscriber("shoal/*/events", keep(events)),
    ]
    time.sleep(0.5)

    def submit(payload: bytes):
        for reply in session.get("shoal/submit", payload=payload, timeout=10.0):
            if reply.ok is not None:
                return json.loads(reply.ok.payload.to_bytes())
        return None

    # A malformed submission is refused with a reason, and the server keeps serving.
    refusal = submit(b"this is not json")
    if not refusal or refusal.get("accepted") is not False or not refusal.get("error"):
        print(f"a malformed submission was not refused: {refusal}", file=sys.stderr)
        return 1

    with open(a.scenario, encoding="utf-8") as f:
        scenario = f.read()
    receipt = submit(json.dumps({
        "version": 1,
        "scenario_toml": scenario,
        "mission": "py-interop",
        "time_scale": a.time_scale,
        "iterations": a.iterations,
        "in_process": True,
    }).encode())
    if not receipt or not receipt.get("accepted"):
        print(f"the submission was not accepted: {receipt}", file=sys.stderr)
        return 1
    mission = receipt["mission"]

    status = None
    deadline = time.time() + a.timeout
    while time.time() < deadline:
        with lock:
            ended = any(e.get("mission") == mission and e.get("kind") == "mission_end" for _, e in events)
            reports = [t for k, t in telemetry if t.get("mission") == mission]
        if status is None and len(reports) >= 6:
            for reply in session.get(f"shoal/{mission}/status", timeout=5.0):
                if reply.ok is not None:
                    status = json.loads(reply.ok.payload.to_bytes())
        if ended:
            break
        time.sleep(0.2)

    with lock:
        mine_plans = [p for k, p in plans if k == f"shoal/{mission}/plan"]
        reports = [t for k, t in telemetry if k.startswith(f"shoal/{mission}/telemetry/")]
        kinds = [e.get("kind") for _, e in events if e.get("mission") == mission]
    for s in subs:
        s.undeclare()
    session.close()

    vehicles = sorted({t["vehicle"] for t in reports})
    summary = {
        "mission": mission,
        "plans": len(mine_plans),
        "plan_vehicles": [v for v, _ in mine_plans[0]["trajectories"]] if mine_plans else [],
        "reports": len(reports),
        "vehicles": vehicles,
        "statuses": [r["state"]["status"] for r in reports][-3:],
        "status_vehicles": [v["vehicle"] for v in status["vehicles"]] if status else [],
        "events": kinds,
    }
    print(json.dumps(summary))
    problems = []
    if not mine_plans or mine_plans[0].get("revision") != 0:
        problems.append("no plan of revision 0")
    elif any(len(samples) < 2 for _, samples in mine_plans[0]["trajectories"]):
        problems.append("a plan trajectory has fewer than 2 samples")
    if len(vehicles) < 3:
        problems.append(f"telemetry from {vehicles} only")
    if not status or len(status.get("vehicles", [])) != 3:
        problems.append(f"no usable status answer: {status}")
    if "mission_end" not in kinds:
        problems.append("no mission_end event before the timeout")
    if problems:
        print("; ".join(problems), file=sys.stderr)
        return 1
    return 0


if __name__ == "__main__":
    sys.exit(main())
