"""Independent reader of `shoal-coordinator export`: geojson 3.3.0 and shapely 2.2.0 read
`plan.geojson`, plain JSON reads the QGroundControl `.plan` files, and PROJ (pyproj 3.7.2)
converts the scenario's own metres to WGS-84 with no Rust involved.

    python check_export.py SCENARIO.toml PLAN.json GEOJSON QGC_DIR

The origin comes from the scenario's [origin] table; every position in the exports must be
within 1 cm (horizontally, along the ellipsoid, and vertically) of the scenario point it stands
for: latitude and longitude of the tangent plane's point (x, y, 0) by PROJ's topocentric
(east-north-up) transform on WGS-84, altitude the origin's plus z (Shoal's z is an altitude:
its surface follows the Earth, not the plane).

Prints one JSON summary line on stdout; exit 0 when every check passed, 1 otherwise (the reason
on stderr).
"""

import json
import math
import sys
import tomllib
from pathlib import Path

import geojson
import shapely
from pyproj import Geod, Transformer

TOL_M = 0.01
CIRCLE_VERTICES = 64
NAV_WAYPOINT, DO_CHANGE_SPEED = 16, 178
GEOD = Geod(ellps="WGS84")


class Failed(Exception):
    pass


def need(ok, what):
    if not ok:
        raise Failed(what)


def enu_to_geodetic(origin):
    """scenario point (x, y, z) -> (lon, lat, alt): PROJ for (x, y, 0), alt = origin + z."""
    t = Transformer.from_pipeline(
        "+proj=pipeline +step +proj=unitconvert +xy_in=deg +xy_out=rad "
        "+step +proj=cart +ellps=WGS84 "
        f"+step +proj=topocentric +ellps=WGS84 +lat_0={origin['lat_deg']!r} "
        f"+lon_0={origin['lon_deg']!r} +h_0={origin['alt_m']!r}"
    )
    def convert(p):
        lon, lat, _ = t.transform(p[0], p[1], 0.0, direction="INVERSE")
        return lon, lat, origin["alt_m"] + p[2]

    return convert


def near(actual_lon_lat, expected, what, alt=None):
    """Within TOL_M of `expected` (lon, lat, h) along the ellipsoid (and in altitude)."""
    lon, lat = actual_lon_lat
    _, _, d = GEOD.inv(lon, lat, expected[0], expected[1])
    need(d <= TOL_M, f"{what}: {d:.4f} m from where PROJ puts it")
    if alt is not None:
        need(abs(alt - expected[2]) <= TOL_M, f"{what}: altitude {alt} vs {expected[2]}")


def check_ring(coords, what, ccw):
    need(coords[0] == coords[-1], f"{what}: ring not closed")
    ring = shapely.LinearRing([c[:2] for c in coords])
    need(ring.is_ccw == ccw, f"{what}: ring winds the wrong way")


def check_geojson(path, scenario, plan, to_geo):
    with open(path) as f:
        checked = geojson.load(f)
    need(isinstance(checked, geojson.FeatureCollection), "not a FeatureCollection")
    need(checked.is_valid, f"geojson says invalid: {checked.errors()}")
    # geojson rounds what it loads to 6 decimals (10 cm, RFC 7946 §11.2's advice): the
    # positions are compared as written.
    with open(path) as f:
        fc = json.load(f)
    by = {}
    for feat in fc["features"]:
        by.setdefault(feat["properties"]["feature"], []).append(feat)
    for feat in by.get("bounds", []) + by.get("obstacle", []):
        poly = shapely.geometry.shape(feat["geometry"])
        need(poly.is_valid, f"{feat['properties']}: {shapely.is_valid_reason(poly)}")
        check_ring(feat["geometry"]["coordinates"][0], feat["properties"].get("id", "bounds"), True)

    (bounds,) = by["bounds"]
    lo, hi = scenario["bounds"]["min"], scenario["bounds"]["max"]
    corners = [(lo[0], lo[1]), (hi[0], lo[1]), (hi[0], hi[1]), (lo[0], hi[1])]
    ring = bounds["geometry"]["coordinates"][0]
    for k, (x, y) in enumerate(corners):
        near(ring[k], to_geo((x, y, hi[2])), f"bounds corner {k}")

    obstacles = {o["id"]: o for o in scenario["obstacles"]}
    need(sorted(f["properties"]["id"] for f in by["obstacle"]) == sorted(obstacles), "obstacle ids")
    for feat in by["obstacle"]:
        props = feat["properties"]
        o = obstacles[props["id"]]
        r = o["radius_m"] + o["inflation_m"]
        need(props["kind"] == o["kind"] and abs(props["radius_m"] - o["radius_m"]) < 1e-9, props["id"])
        ring = feat["geometry"]["coordinates"][0]
        need(len(ring) == CIRCLE_VERTICES + 1, f"{props['id']}: {len(ring)} positions")
        out = r / math.cos(math.pi / CIRCLE_VERTICES)
        cx, cy, cz = o["centre"]
        for k in range(CIRCLE_VERTICES):
            a = 2 * math.pi * k / CIRCLE_VERTICES
            vertex = (cx + out * math.cos(a), cy + out * math.sin(a), cz)
            near(ring[k], to_geo(vertex), f"{props['id']} vertex {k}")
        need(abs(props["centre_depth_m"] - (hi[2] - cz)) < 1e-3, f"{props['id']} depth")

    paths = {f["properties"]["vehicle"]: f for f in by["path"]}
    waypoints = {}
    for f in by["waypoint"]:
        waypoints.setdefault(f["properties"]["vehicle"], []).append(f)
    starts = {v["id"]: v for v in scenario["vehicles"]}
    for v in plan["vehicles"]:
        samples = v["trajectory"]
        line = paths[v["id"]]["geometry"]["coordinates"]
        need(len(line) == len(samples), f"{v['id']}: {len(line)} positions")
        near(line[0][:2], to_geo(starts[v["id"]]["start"]), f"{v['id']} start", line[0][2])
        near(line[-1][:2], to_geo(starts[v["id"]]["goal"]), f"{v['id']} goal", line[-1][2])
        points = sorted(waypoints[v["id"]], key=lambda f: f["properties"]["index"])
        need(len(points) == len(samples), f"{v['id']}: {len(points)} waypoints")
        for k, (s, pos, pt) in enumerate(zip(samples, line, points)):
            expected = to_geo(s[1:])
            near(pos[:2], expected, f"{v['id']} path {k}", pos[2])
            p = pt["properties"]
            c = pt["geometry"]["coordinates"]
            near(c[:2], expected, f"{v['id']} waypoint {k}", c[2])
            need(p["t_s"] == s[0], f"{v['id']} waypoint {k}: t_s")
            need(abs(p["depth_m"] - (hi[2] - s[3])) < 1e-3, f"{v['id']} waypoint {k}: depth")
            if k + 1 < len(samples):
                n = samples[k + 1]
                speed = math.dist(s[1:], n[1:]) / (n[0] - s[0])
                need(abs(p["speed_mps"] - speed) < 1e-9, f"{v['id']} waypoint {k}: speed")
            else:
                need(p["speed_mps"] is None, f"{v['id']}: last waypoint has a speed")
    return len(fc["features"])


def check_qgc(qgc_dir, scenario, plan, to_geo):
    hard = {o["id"]: o for o in scenario["obstacles"] if o["kind"] == "hard"}
    lo, hi = scenario["bounds"]["min"], scenario["bounds"]["max"]
    starts = {v["id"]: v for v in scenario["vehicles"]}
    waypoints = 0
    for v in plan["vehicles"]:
        with open(Path(qgc_dir) / f"{v['id']}.plan") as f:
            doc = json.load(f)
        what = f"{v['id']}.plan"
        need((doc["fileType"], doc["version"], doc["groundStation"]) == ("Plan", 1, "QGroundControl"), what)
        m = doc["mission"]
        need(m["version"] == 2 and m["vehicleType"] == 12 and isinstance(m["firmwareType"], int), f"{what}: mission header")
        need(m["cruiseSpeed"] > 0 and m["hoverSpeed"] > 0, f"{what}: speeds")
        home = m["plannedHomePosition"]
        near((home[1], home[0]), to_geo(starts[v["id"]]["start"]), f"{what} home", home[2])
        items = m["items"]
        need([i["doJumpId"] for i in items] == list(range(1, len(items) + 1)), f"{what}: doJumpId")
        samples, k, speed = v["trajectory"], 0, None
        for i in items:
            need(i["type"] == "SimpleItem" and i["autoContinue"] is True and len(i["params"]) == 7, f"{what}: item {i}")
            if i["command"] == DO_CHANGE_SPEED:
                need(i["frame"] == 2 and i["params"][0] == 1, f"{what}: speed item {i}")
                speed = i["params"][1]
                continue
            need(i["command"] == NAV_WAYPOINT and i["frame"] == 0 and i["params"][3] is None, f"{what}: item {i}")
            a, b = samples[k], samples[k + 1]
            lat, lon, alt = i["params"][4:]
            near((lon, lat), to_geo(b[1:]), f"{what} waypoint {k + 1}", alt)
            length, dt = math.dist(a[1:], b[1:]), b[0] - a[0]
            if length >= 1e-3:
                need(speed is not None and abs(speed - length / dt) <= 1e-3, f"{what}: leg {k} at {speed}, planned {length / dt}")
                need(i["params"][0] == 0, f"{what}: leg {k} holds")
            else:
                need(abs(i["params"][0] - dt) < 1e-3, f"{what}: wait {k}")
            k += 1
        need(k == len(samples) - 1, f"{what}: {k} waypoints for {len(samples) - 1} legs")
        waypoints += k
        fence = doc["geoFence"]
        need(fence["version"] == 2, f"{what}: geofence version")
        (poly,) = fence["polygons"]
        need(poly["inclusion"] is True and len(poly["polygon"]) == 4, f"{what}: bounds polygon")
        # QGC winds its polygons clockwise: south-west, north-west, north-east, south-east.
        corners = [(lo[0], lo[1]), (lo[0], hi[1]), (hi[0], hi[1]), (hi[0], lo[1])]
        for (lat, lon), (x, y) in zip(poly["polygon"], corners):
            near((lon, lat), to_geo((x, y, hi[2])), f"{what} fence corner")
        ring = [(lon, lat) for lat, lon in poly["polygon"]]
        need(not shapely.LinearRing(ring).is_ccw, f"{what}: fence polygon is not clockwise")
        for c in fence["circles"]:
            need(c["inclusion"] is False and c["version"] == 1, f"{what}: circle {c}")
            lat, lon = c["circle"]["center"]
            matches = [
                o for o in hard.values()
                if abs(c["circle"]["radius"] - o["radius_m"] - o["inflation_m"]) < 1e-9
                and GEOD.inv(lon, lat, *to_geo(o["centre"])[:2])[2] <= TOL_M
            ]
            need(len(matches) == 1, f"{what}: circle {c} is no hard obstacle")
        need(doc["rallyPoints"] == {"version": 2, "points": []}, f"{what}: rally points")
    return waypoints


def main() -> int:
    scenario_path, plan_path, geojson_path, qgc_dir = sys.argv[1:5]
    with open(scenario_path, "rb") as f:
        scenario = tomllib.load(f)
    with open(plan_path) as f:
        plan = json.load(f)
    to_geo = enu_to_geodetic(scenario["origin"])
    try:
        features = check_geojson(geojson_path, scenario, plan, to_geo)
        waypoints = check_qgc(qgc_dir, scenario, plan, to_geo)
    except (Failed, KeyError, ValueError, TypeError) as e:
        print(f"check_export: {type(e).__name__}: {e}", file=sys.stderr)
        return 1
    print(json.dumps({"ok": True, "features": features, "qgc_waypoints": waypoints}))
    return 0


if __name__ == "__main__":
    sys.exit(main())
