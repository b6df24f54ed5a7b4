"""Independent client of Shoal's web view and Foxglove server beyond loopback, with Python's own
`ssl` and `http.client`, the `websockets` package (17.4) and `eclipse-zenoh` (1.10.2): nothing
here is Shoal's code.

    python secured_watch.py KEYS_DIR ENDPOINT VIEW_PORT FOXGLOVE_PORT SCENARIO OUT.json

As the operator (`KEYS_DIR/operator.pem`, signed by the fleet CA `KEYS_DIR/ca.pem`), it submits
SCENARIO to `serve` over the mutually authenticated Zenoh ENDPOINT, then, on 127.0.0.1:
- GETs the view's page over HTTPS (200, the page itself), opens the view's WebSocket over WSS
  and reads until the catch-up is complete and a report has arrived;
- opens the Foxglove server over WSS (`foxglove.websocket.v1`), reads the advertised channels,
  subscribes to a pose channel and waits for one pose message.
Then, on both ports, it checks the refusals: TLS without a client certificate, with a vehicle's
certificate (`auv1`), and plain HTTP / ws to the TLS port must all fail. Last, the operator
must still get the page and the Foxglove channels (the refusals did not take the servers down).

Writes OUT.json with what it saw; exit 0 when every check passed, 1 otherwise (the reasons on
stderr).
"""

import argparse
import http.client
import json
import os
import ssl
import struct
import sys
import time

import zenoh
from websockets.sync.client import connect

SUBPROTOCOL = "foxglove.websocket.v1"
HOST = "127.0.0.1"
MESSAGE_DATA = struct.Struct("<BIQ")


def context(keys, member):
    """A TLS client context trusting the fleet CA, presenting `member`'s certificate (or none)."""
    ctx = ssl.SSLContext(ssl.PROTOCOL_TLS_CLIENT)
    ctx.load_verify_locations(os.path.join(keys, "ca.pem"))
    if member is not None:
        ctx.load_cert_chain(os.path.join(keys, member + ".pem"), os.path.join(keys, member + ".key"))
    return ctx


def get_page(port, ctx):
    """(status, body) of GET / over HTTPS (ctx) or plain HTTP (None)."""
    if ctx is None:
        conn = http.client.HTTPConnection(HOST, port, timeout=10)
    else:
        conn = http.client.HTTPSConnection(HOST, port, timeout=10, context=ctx)
    try:
        conn.request("GET", "/")
        r = conn.getresponse()
        return r.status, r.read().decode("utf-8", "replace")
    finally:
        conn.close()


def get_page_retrying(port, ctx, seconds=60.0):
    deadline = time.monotonic() + seconds
    while True:
        try:
            return get_page(port, ctx)
        except OSError:
            if time.monotonic() > deadline:
                raise
            time.sleep(0.3)


def watch_view(port, ctx, seconds=120.0):
    """The view's WebSocket: the kinds of message received until caught up and a report came."""
    kinds = set()
    deadline = time.monotonic() + seconds
    with connect(f"wss://{HOST}:{port}/ws", ssl=ctx, open_timeout=10, max_size=None) as ws:
        while time.monotonic() < deadline:
            frame = json.loads(ws.recv(timeout=max(0.1, deadline - time.monotonic())))
            kinds.update(m.get("kind") for m in frame)
            if "caught_up" in kinds and "telemetry" in kinds:
                break
    return sorted(k for k in kinds if k)


def watch_foxglove(port, ctx, seconds=120.0):
    """The Foxglove server: its channels' topics, and whether a pose message arrived."""
    topics = {}
    got_pose = False
    deadline = time.monotonic() + seconds
    with connect(f"wss://{HOST}:{port}", ssl=ctx, subprotocols=[SUBPROTOCOL], open_timeout=10,
                 max_size=None) as ws:
        subscribed = False
        while time.monotonic() < deadline and not got_pose:
            m = ws.recv(timeout=max(0.1, deadline - time.monotonic()))
            if isinstance(m, bytes):
                op, sub, _ = MESSAGE_DATA.unpack_from(m)
                got_pose = got_pose or (op == 1 and sub == 1)
                continue
            m = json.loads(m)
            if m.get("op") == "advertise":
                for c in m["channels"]:
                    topics[c["id"]] = c["topic"]
                poses = [i for i, t in topics.items() if t.startswith("/shoal/pose/")]
                if poses and not subscribed:
                    ws.send(json.dumps({"op": "subscribe",
                                        "subscriptions": [{"id": 1, "channelId": poses[0]}]}))
                    subscribed = True
    return sorted(topics.values()), got_pose


def refused(what):
    """Runs `what`; (True, the error) if it failed, (False, its result) if it worked."""
    try:
        result = what()
    except Exception as e:  # ssl.SSLError, ConnectionError, http.client or websockets errors
        return True, f"{type(e).__name__}: {e}"[:200]
    return False, repr(result)[:200]


def submit(keys, endpoint, scenario):
    conf = zenoh.Config.from_file(os.path.join(keys, "operator.json5"))
    conf.insert_json5("mode", '"client"')
    conf.insert_json5("connect/endpoints", json.dumps([endpoint]))
    conf.insert_json5("scouting/multicast/enabled", "false")
    deadline = time.monotonic() + 60
    while True:
        try:
            session = zenoh.open(conf)
            break
        except Exception:
            if time.monotonic() > deadline:
                raise
            time.sleep(0.3)
    with open(scenario) as f:
        text = f.read()
    sub = {"version": 1, "scenario_toml": text, "mission": "watched", "time_scale": 20.0,
           "iterations": 20}
    answers = []
    for reply in session.get("shoal/submit", payload=json.dumps(sub).encode(), timeout=10.0):
        if reply.ok is not None:
            answers.append(json.loads(reply.ok.payload.to_bytes()))
    session.close()
    return answers


def main() -> int:
    ap = argparse.ArgumentParser()
    ap.add_argument("keys")
    ap.add_argument("endpoint")
    ap.add_argument("view_port", type=int)
    ap.add_argument("foxglove_port", type=int)
    ap.add_argument("scenario")
    ap.add_argument("out")
    a = ap.parse_args()
    operator = context(a.keys, "operator")
    failures = []
    out = {}

    def need(ok, what):
        if not ok:
            failures.append(what)

    status, body = get_page_retrying(a.view_port, operator)
    out["page_status"] = status
    need(status == 200 and "Shoal — live view" in body, f"the page over HTTPS: {status}")
    answers = submit(a.keys, a.endpoint, a.scenario)
    out["submission"] = answers
    need(answers and answers[0].get("accepted"), f"the submission was refused: {answers}")
    out["view_kinds"] = watch_view(a.view_port, operator)
    need({"hello", "caught_up", "telemetry"} <= set(out["view_kinds"]),
         f"the view's WebSocket over WSS: {out['view_kinds']}")
    topics, pose = watch_foxglove(a.foxglove_port, operator)
    out["foxglove_topics"], out["foxglove_pose"] = topics, pose
    need("/shoal/scene" in topics and any(t.startswith("/shoal/pose/") for t in topics),
         f"the Foxglove channels over WSS: {topics}")
    need(pose, "no pose message over WSS")

    stranger, vehicle = context(a.keys, None), context(a.keys, "auv1")
    attempts = {
        "view_without_certificate": lambda: get_page(a.view_port, stranger),
        "view_vehicle": lambda: get_page(a.view_port, vehicle),
        "view_plain_http": lambda: get_page(a.view_port, None),
        "view_ws_vehicle": lambda: watch_view(a.view_port, vehicle, 5.0),
        "foxglove_without_certificate": lambda: watch_foxglove(a.foxglove_port, stranger, 5.0),
        "foxglove_vehicle": lambda: watch_foxglove(a.foxglove_port, vehicle, 5.0),
        "foxglove_plain_ws": lambda: connect(f"ws://{HOST}:{a.foxglove_port}",
                                             subprotocols=[SUBPROTOCOL], open_timeout=5).close(),
    }
    out["refusals"] = {}
    for name, attempt in attempts.items():
        ok, detail = refused(attempt)
        out["refusals"][name] = detail
        need(ok, f"{name} was not refused: {detail}")

    status, body = get_page(a.view_port, operator)
    out["page_status_after"] = status
    need(status == 200 and "Shoal — live view" in body, f"the page afterwards: {status}")
    topics, pose = watch_foxglove(a.foxglove_port, operator)
    out["foxglove_after"] = {"topics": len(topics), "pose": pose}
    need(topics and pose, "Foxglove afterwards: no channels or no pose")

    out["failures"] = failures
    with open(a.out, "w") as f:
        json.dump(out, f, indent=1)
    for f in failures:
        print(f, file=sys.stderr)
    return 1 if failures else 0


if __name__ == "__main__":
    sys.exit(main())
