"""Waypoint kinematics shared by the test vehicles (`mavsdk_vehicle.py`, `ardupilot_vehicle.py`).

A vehicle here moves in a straight line from where it is to each waypoint of its mission, in real
time, as the MAVLink mission items say (https://mavlink.io/en/messages/common.html):

- MAV_CMD_DO_CHANGE_SPEED (178): speed type (param1) 0 or 1 sets the horizontal speed of the
  legs that follow, 2 the climb and 3 the descent speed (param2, m/s; a value <= 0 changes nothing);
- MAV_CMD_NAV_WAYPOINT (16): a leg at the horizontal speed in force, with whatever vertical speed
  reaches the waypoint's altitude at the same moment; a purely vertical leg goes at the climb or
  descent speed (the horizontal one if none was set). There it waits param1 seconds, and only
  then is the item complete, as ArduSub's `verify_nav_wp` and PX4's mission block do. Latitude
  and longitude 0, 0 mean "here" (ArduSub's `do_nav_wp`);
- any other item completes as soon as the mission reaches it.

Altitude is AMSL in MAV_FRAME_GLOBAL(_INT) (0, 5) and above home in the relative frames (3, 6).

Distances are taken in the tangent plane at each leg's start with the WGS-84 radii of curvature
(meridian M, prime vertical N; NIMA TR8350.2, "Department of Defense World Geodetic System 1984",
ch. 3 and 4): an implementation of its own, not the link's spherical approximation, so a test
comparing the two compares independent code (they differ by ~0.5 %, centimetres on these legs).

A `Runner` owns the mission clock: it runs while the vehicle is underway and stands still while it
holds, so holding freezes the vehicle where it is, mid-leg or not.

    python vehicle_kinematics.py   # runs the self-test
"""

import json
import math
from dataclasses import dataclass, field

WGS84_A = 6_378_137.0  # semi-major axis, m
WGS84_E2 = 6.694_379_990_14e-3  # first eccentricity squared

NAV_WAYPOINT = 16
DO_CHANGE_SPEED = 178
ABSOLUTE_FRAMES = (0, 5)  # MAV_FRAME_GLOBAL, MAV_FRAME_GLOBAL_INT
RELATIVE_FRAMES = (3, 6)  # MAV_FRAME_GLOBAL_RELATIVE_ALT, MAV_FRAME_GLOBAL_RELATIVE_ALT_INT


def emit(record):
    """Prints `record` as one JSON line, NaN and infinities as null (JSON has neither)."""

    def clean(v):
        if isinstance(v, float) and not math.isfinite(v):
            return None
        if isinstance(v, dict):
            return {k: clean(x) for k, x in v.items()}
        if isinstance(v, (list, tuple)):
            return [clean(x) for x in v]
        return v

    print(json.dumps(clean(record)), flush=True)


def parse_home(text):
    """`LAT,LON,ALT` (a vehicle's `--home`) as a tuple of floats."""
    lat, lon, alt = (float(v) for v in text.split(","))
    return lat, lon, alt


def radii(lat_deg):
    """(M, N): the meridian and prime-vertical radii of curvature at `lat_deg`, metres."""
    s = math.sin(math.radians(lat_deg))
    w = 1.0 - WGS84_E2 * s * s
    return WGS84_A * (1.0 - WGS84_E2) / w**1.5, WGS84_A / math.sqrt(w)


def enu(ref, p):
    """(east, north, up) metres of `p` from `ref`, both (lat deg, lon deg, alt m)."""
    m, n = radii(ref[0])
    east = math.radians(p[1] - ref[1]) * n * math.cos(math.radians(ref[0]))
    return east, math.radians(p[0] - ref[0]) * m, p[2] - ref[2]


def geodetic(ref, east, north, up):
    """The point `east`, `north`, `up` metres from `ref`, as (lat deg, lon deg, alt m)."""
    m, n = radii(ref[0])
    lon = ref[1] + math.degrees(east / (n * math.cos(math.radians(ref[0]))))
    return ref[0] + math.degrees(north / m), lon, ref[2] + up


@dataclass
class Leg:
    """The way to one waypoint: where from, where to, how fast, and when on the mission clock."""

    seq: int  # the waypoint's item number
    start: tuple  # (lat, lon, alt)
    end: tuple
    speed: float  # horizontal speed used, m/s
    speed_from: object  # seq of the DO_CHANGE_SPEED that set it, None for the default
    vspeed: float  # vertical speed, m/s, positive up
    hold_s: float
    depart_s: float
    travel_s: float
    before: list = field(default_factory=list)  # items that complete as the leg begins

    @property
    def offset(self):
        return enu(self.start, self.end)

    @property
    def length_m(self):
        return math.sqrt(sum(c * c for c in self.offset))

    @property
    def done_s(self):
        return self.depart_s + self.travel_s + self.hold_s

    def report(self):
        """The leg as a JSON-ready dict (the vehicles print it)."""
        return {
            "seq": self.seq,
            "speed": self.speed,
            "speed_from": self.speed_from,
            "vspeed": self.vspeed,
            "hold_s": self.hold_s,
            "depart_s": self.depart_s,
            "travel_s": self.travel_s,
            "length_m": self.length_m,
        }


class Track:
    """Mission items `items` (dicts with seq, command, frame, param1, param2, x, y, z) from
    `first` on, driven from `start` (lat, lon, alt); `home_alt` is the relative frames' zero."""

    def __init__(self, start, items, default_speed, home_alt, first=0):
        self.start, self.legs, self.after = tuple(start), [], []
        here, clock = self.start, 0.0
        speed, speed_from, climb, descent, pending = default_speed, None, None, None, []
        for item in items[first:]:
            seq, command = item["seq"], item["command"]
            if command == DO_CHANGE_SPEED:
                kind, value = int(item["param1"]), float(item["param2"])
                if value > 0 and kind in (0, 1):
                    speed, speed_from = value, seq
                elif value > 0 and kind == 2:
                    climb = value
                elif value > 0 and kind == 3:
                    descent = value
            if command != NAV_WAYPOINT:
                pending.append(seq)
                continue
            end = self._target(item, here, home_alt)
            east, north, up = enu(here, end)
            horizontal = math.hypot(east, north)
            if horizontal > 1e-3:
                travel = horizontal / speed
            elif abs(up) > 1e-3:
                travel = abs(up) / ((climb if up > 0 else descent) or speed)
            else:
                travel = 0.0
            hold = max(0.0, float(item["param1"]))
            vspeed = up / travel if travel > 0 else 0.0
            leg = Leg(seq, here, end, speed, speed_from, vspeed, hold, clock, travel, pending)
            self.legs.append(leg)
            here, clock, pending = end, leg.done_s, []
        self.after, self.duration_s, self.end = pending, clock, here

    @staticmethod
    def _target(item, here, home_alt):
        lat, lon = item["x"] / 1e7, item["y"] / 1e7
        if item["x"] == 0 and item["y"] == 0:
            lat, lon = here[0], here[1]
        alt = float(item["z"])
        if item["frame"] in RELATIVE_FRAMES:
            alt += home_alt
        return lat, lon, alt

    def leg_at(self, t):
        """The leg under way (or waiting) at mission time `t`; None before and after them all."""
        for leg in self.legs:
            if leg.depart_s <= t < leg.done_s:
                return leg
        return None

    def position_at(self, t):
        """(lat, lon, alt) at mission time `t`."""
        leg = self.leg_at(t)
        if leg is None:
            return self.start if t < 0 else self.end
        if leg.travel_s <= 0 or t >= leg.depart_s + leg.travel_s:
            return leg.end
        f = (t - leg.depart_s) / leg.travel_s
        east, north, up = leg.offset
        return geodetic(leg.start, east * f, north * f, up * f)

    def velocity_at(self, t):
        """(east, north, up) m/s at mission time `t`."""
        leg = self.leg_at(t)
        if leg is None or not leg.depart_s <= t < leg.depart_s + leg.travel_s:
            return 0.0, 0.0, 0.0
        return tuple(c / leg.travel_s for c in leg.offset)

    def along_at(self, t):
        """Path length travelled by mission time `t`, metres."""
        total = 0.0
        for leg in self.legs:
            if t <= leg.depart_s:
                break
            f = 1.0 if leg.travel_s <= 0 else min(1.0, (t - leg.depart_s) / leg.travel_s)
            total += f * leg.length_m
        return total

    def completed_by(self, t):
        """Item numbers complete by mission time `t`, in mission order."""
        done = []
        for leg in self.legs:
            if t < leg.depart_s:
                return done
            done += leg.before
            if t < leg.done_s:
                return done
            done.append(leg.seq)
        return done + (self.after if t >= self.duration_s else [])


class Runner:
    """The vehicle's motion: a track driven on a mission clock that holding stops."""

    def __init__(self, home):
        self.home = tuple(home)  # where the vehicle started
        self.track = None
        self.clock = 0.0
        self.holding = False
        self.reported = 0  # how many of track.completed_by() were handed out
        self.here = self.home
        self.heading_deg = 0.0  # clockwise from north, the last direction of travel

    def start(self, items, default_speed, home_alt, first=0):
        """Drives `items` from where the vehicle is now; returns the track."""
        self.track = Track(self.here, items, default_speed, home_alt, first)
        self.clock, self.holding, self.reported = 0.0, False, 0
        return self.track

    def stop(self):
        """Forgets the mission (a new one is coming): the vehicle stays where it is."""
        self.track = None

    def advance(self, dt):
        """Moves on by `dt` seconds of real time (none while holding or idle)."""
        if self.track is None:
            return
        if not self.holding:
            self.clock += dt
        self.here = self.track.position_at(self.clock)
        east, north, _ = self.velocity()
        if math.hypot(east, north) > 1e-6:
            self.heading_deg = math.degrees(math.atan2(east, north)) % 360.0

    def velocity(self):
        if self.track is None or self.holding:
            return 0.0, 0.0, 0.0
        return self.track.velocity_at(self.clock)

    def newly_completed(self):
        """Items completed since the last call, in mission order."""
        if self.track is None:
            return []
        done = self.track.completed_by(self.clock)
        fresh, self.reported = done[self.reported :], len(done)
        return fresh

    @property
    def finished(self):
        return self.track is not None and self.clock >= self.track.duration_s

    @property
    def state(self):
        if self.track is None:
            return "idle"
        if self.holding:
            return "holding"
        return "done" if self.finished else "underway"

    def report(self):
        """The vehicle's position as a JSON-ready dict (the vehicles' 1 Hz `position` line)."""
        east, north, up = enu(self.home, self.here)
        along = self.track.along_at(self.clock) if self.track else 0.0
        return {
            "lat": self.here[0],
            "lon": self.here[1],
            "alt": self.here[2],
            "east_m": east,
            "north_m": north,
            "up_m": up,
            "along_m": along,
            "clock_s": self.clock,
            "state": self.state,
        }


def _self_test():
    """Known answers: a 100 m east leg at 2 m/s then a 10 m dive, a hold, and a pause."""
    home = (43.1, 5.9, -5.0)
    east100 = geodetic(home, 100.0, 0.0, 0.0)
    keys = ("seq", "command", "frame", "param1", "param2", "x", "y", "z")
    lat, lon = (round(deg * 1e7) for deg in east100[:2])
    rows = [
        (0, DO_CHANGE_SPEED, 2, 1, 2.0, 0, 0, 0.0),  # ground speed 2 m/s
        (1, NAV_WAYPOINT, 5, 3.0, 0, lat, lon, -5.0),  # 100 m east, AMSL, wait 3 s
        (2, DO_CHANGE_SPEED, 2, 3, 0.5, 0, 0, 0.0),  # descent 0.5 m/s
        (3, NAV_WAYPOINT, 6, 0.0, 0, 0, 0, -15.0),  # here, 15 m under home (alt 0)
    ]
    items = [dict(zip(keys, row)) for row in rows]
    track = Track(home, items, default_speed=1.0, home_alt=0.0)
    a, b = track.legs
    assert abs(a.travel_s - 50.0) < 0.05 and a.speed_from == 0 and a.before == [0], a
    assert abs(b.depart_s - 53.0) < 0.05 and abs(b.travel_s - 20.0) < 0.05, b  # 10 m down at 0.5
    assert abs(b.vspeed + 0.5) < 1e-3 and b.before == [2], b
    half = enu(home, track.position_at(25.0))
    assert abs(half[0] - 50.0) < 0.05 and abs(half[1]) < 0.05, half
    assert track.completed_by(49.0) == [0] and track.completed_by(53.1) == [0, 1, 2], track
    assert track.completed_by(80.0) == [0, 1, 2, 3] and abs(track.along_at(80.0) - 110.0) < 0.05
    assert abs(enu(home, track.position_at(80.0))[2] + 10.0) < 1e-6
    run = Runner(home)
    run.start(items, 1.0, 0.0)
    run.advance(10.0)
    run.holding = True
    run.advance(30.0)  # holding: the clock stands still
    assert abs(enu(home, run.here)[0] - 20.0) < 0.05 and run.velocity() == (0.0, 0.0, 0.0)
    assert run.newly_completed() == [0] and run.newly_completed() == []
    run.holding = False
    run.advance(100.0)
    assert run.finished and run.newly_completed() == [1, 2, 3] and run.state == "done"
    print("vehicle_kinematics: ok")


if __name__ == "__main__":
    _self_test()
