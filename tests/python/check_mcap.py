"""Independent reader of Shoal's MCAP mission logs: the `mcap` package (1.6.0, Foxglove's Python
library) reads `mission.mcap`, `jsonschema` (4.26.0) checks every channel's schema and validates
every message against it, and plain JSON reads `mission.ndjson`, the log of the same run.

    python check_mcap.py MISSION.ndjson MISSION.mcap [MORE.mcap ...]

Every MCAP file must hold exactly the NDJSON log's records: message n (its sequence number) is
line n without its "record" tag, on the topic of its kind (`/shoal/<kind>`, reports on
`/shoal/telemetry/<vehicle>`), so the counts per kind and per vehicle match; every report's
position is the line's within 0.01 m; log times are mission time in nanoseconds (a report's
when it was received, an event's its t_s). When several MCAP files are given they must hold the
same messages with the same times.

Prints one JSON summary line on stdout; exit 0 when every check passed, 1 otherwise (the reason
on stderr).
"""

import json
import sys
from collections import Counter

import jsonschema
from mcap.reader import make_reader

TOL_M = 0.01
KINDS = ("start", "plan", "telemetry", "event", "obstacle", "end")


class Failed(Exception):
    pass


def need(ok, what):
    if not ok:
        raise Failed(what)


def topic_of(record):
    if record["record"] == "telemetry":
        return "/shoal/telemetry/" + record["telemetry"]["vehicle"]
    return "/shoal/" + record["record"]


def mission_ns(start, unix_us):
    seconds = (unix_us - start["epoch_unix_ms"] * 1000) / 1e6 * start["time_scale"]
    return max(0, round(seconds * 1e9))


def read_mcap(path):
    """Every message as (sequence, topic, log_time, publish_time, JSON), and the validators."""
    validators = {}
    messages = []
    with open(path, "rb") as f:
        reader = make_reader(f)
        header = reader.get_header()
        need(header.library.startswith("shoal-coordinator"), f"{path}: library {header.library!r}")
        # File order: log times follow each record's own time, so they may run a little
        # backwards between records (a report is stamped when it arrived, an event when the
        # loop made it); the sequence numbers give the order, checked below.
        for schema, channel, message in reader.iter_messages(log_time_order=False):
            topic = channel.topic
            need(channel.message_encoding == "json", f"{path}: {topic} is encoded {channel.message_encoding!r}")
            need(schema is not None, f"{path}: {topic} has no schema")
            need(schema.encoding == "jsonschema", f"{path}: {topic}'s schema is {schema.encoding!r}")
            if topic not in validators:
                doc = json.loads(schema.data)
                cls = jsonschema.validators.validator_for(doc)
                need(cls is jsonschema.Draft202012Validator, f"{path}: {topic}'s schema is {cls.__name__}")
                try:
                    cls.check_schema(doc)
                except jsonschema.SchemaError as e:
                    raise Failed(f"{path}: {topic}'s schema is no JSON Schema: {e.message}")
                validators[topic] = (schema.name, cls(doc))
            data = json.loads(message.data)
            errors = sorted(validators[topic][1].iter_errors(data), key=str)
            need(not errors, f"{path}: message {message.sequence} on {topic} does not match its schema: "
                 + "; ".join(e.message for e in errors[:3]))
            messages.append((message.sequence, topic, message.log_time, message.publish_time, data))
    messages.sort(key=lambda m: m[0])
    return messages, validators


def check(ndjson, path):
    messages, validators = read_mcap(path)
    need(len(messages) == len(ndjson), f"{path}: {len(messages)} messages, the NDJSON log has {len(ndjson)} records")
    start = ndjson[0]
    need(start["record"] == "start", "the NDJSON log does not start with its start record")
    counts, reports = Counter(), Counter()
    latest = 0
    for k, (sequence, topic, log_time, publish_time, data) in enumerate(messages):
        need(sequence == k + 1, f"{path}: message {k + 1} has sequence number {sequence}")
        record = ndjson[k]
        kind = record["record"]
        need(topic == topic_of(record), f"{path}: message {sequence} is on {topic}, line {k + 1} is a {kind} record")
        need(validators[topic][0] == "shoal." + kind, f"{path}: {topic}'s schema is {validators[topic][0]}")
        expected = {key: value for key, value in record.items() if key != "record"}
        need(data == expected, f"{path}: message {sequence} differs from line {k + 1}")
        counts[kind] += 1
        if kind == "telemetry":
            vehicle = record["telemetry"]["vehicle"]
            reports[vehicle] += 1
            mcap_pos = data["telemetry"]["state"]["position"]
            line_pos = record["telemetry"]["state"]["position"]
            need(all(abs(a - b) <= TOL_M for a, b in zip(mcap_pos, line_pos, strict=True)),
                 f"{path}: {vehicle}'s report {record['telemetry']['seq']} at {mcap_pos}, the log has {line_pos}")
            want = mission_ns(start, record["received_unix_us"])
            need(abs(log_time - want) <= 1000, f"{path}: report {sequence} logged at {log_time} ns, received at {want}")
            want = mission_ns(start, record["telemetry"]["sent_unix_us"])
            need(abs(publish_time - want) <= 1000, f"{path}: report {sequence} published at {publish_time} ns, sent at {want}")
        elif kind == "event":
            want = max(0, round(record["t_s"] * 1e9))
            need(abs(log_time - want) <= 1000, f"{path}: event {sequence} logged at {log_time} ns, its t_s is {record['t_s']}")
        elif kind == "start":
            need(log_time == 0, f"{path}: the start record is logged at {log_time} ns")
        else:
            need(log_time == latest, f"{path}: the {kind} record {sequence} is logged at {log_time} ns, not at the latest time before it, {latest}")
        latest = max(latest, log_time)
    expected_counts = Counter(r["record"] for r in ndjson)
    need(counts == expected_counts, f"{path}: kinds {dict(counts)}, the NDJSON log has {dict(expected_counts)}")
    expected_reports = Counter(r["telemetry"]["vehicle"] for r in ndjson if r["record"] == "telemetry")
    need(reports == expected_reports, f"{path}: reports {dict(reports)}, the NDJSON log has {dict(expected_reports)}")
    return messages, counts, reports


def main():
    if len(sys.argv) < 3:
        print(__doc__, file=sys.stderr)
        return 2
    with open(sys.argv[1]) as f:
        ndjson = [json.loads(line) for line in f if line.strip()]
    try:
        first = None
        for path in sys.argv[2:]:
            messages, counts, reports = check(ndjson, path)
            if first is None:
                first = messages
            else:
                need(messages == first, f"{path}: its messages differ from {sys.argv[2]}'s")
    except Failed as e:
        print(f"check_mcap: {e}", file=sys.stderr)
        return 1
    print(json.dumps({
        "files": len(sys.argv) - 2,
        "messages": len(first),
        "channels": len({m[1] for m in first}),
        "kinds": {k: counts[k] for k in KINDS},
        "reports": dict(sorted(reports.items())),
    }))
    return 0


if __name__ == "__main__":
    sys.exit(main())
