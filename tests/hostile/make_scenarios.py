#!/usr/bin/env python3
"""Writes the hostile scenario corpus: shipped scenarios from `scenarios/`, each with one field
made hostile (huge, zero, negative, NaN/inf, 1e-300, 1e300, wrong type, missing, empty, a
device or a system file as a data file), and `manifest.tsv` saying what each must give:

    file<TAB>error<TAB>text   loading it the way `plan` does fails, naming `text` (the field)
    file<TAB>plan<TAB>-       it loads, and `plan --in-process` with a small budget plans it
    file<TAB>plan-error<TAB>text  it loads, and `plan` exits 1 naming `text`

The generated files are committed; run `python3 tests/hostile/make_scenarios.py` from the
repository root after changing this script, and commit what it writes. The test is
`tests/tests/hostile_scenarios.rs`.
"""

import pathlib
import re

ROOT = pathlib.Path(__file__).resolve().parents[2]
OUT = ROOT / "tests" / "hostile" / "scenarios"


def tables(text):
    """(start, end) line spans of each table: header line to the line before the next header."""
    lines = text.split("\n")
    heads = [i for i, l in enumerate(lines) if re.match(r"^\s*\[", l)]
    return lines, [(h, (heads[k + 1] if k + 1 < len(heads) else len(lines))) for k, h in enumerate(heads)]


def header_of(line):
    return line.split("#")[0].strip()


def find(text, header, nth):
    lines, spans = tables(text)
    hits = [s for s in spans if header_of(lines[s[0]]) == header]
    return lines, (hits[nth] if nth < len(hits) else None)


def set_key(text, header, key, value, nth=0):
    """`key = value` in the nth table `header` (replaced, else added; the table is appended if
    it is missing)."""
    lines, span = find(text, header, nth)
    if span is None:
        return text.rstrip("\n") + f"\n\n{header}\n{key} = {value}\n"
    start, end = span
    for i in range(start + 1, end):
        if re.match(rf"^\s*{re.escape(key)}\s*=", lines[i]):
            lines[i] = f"{key} = {value}"
            return "\n".join(lines)
    lines.insert(start + 1, f"{key} = {value}")
    return "\n".join(lines)


def del_key(text, header, key, nth=0):
    lines, span = find(text, header, nth)
    assert span is not None, (header, key)
    start, end = span
    kept = [l for i, l in enumerate(lines) if not (start < i < end and re.match(rf"^\s*{re.escape(key)}\s*=", l))]
    assert len(kept) == len(lines) - 1, (header, key)
    return "\n".join(kept)


def drop_tables(text, prefix):
    """Removes every table whose header starts with `prefix` (e.g. `[seabed` or `[[hazards`)."""
    lines, spans = tables(text)
    drop = set()
    for s, e in spans:
        if header_of(lines[s]).startswith(prefix):
            drop.update(range(s, e))
    return "\n".join(l for i, l in enumerate(lines) if i not in drop)


def drop_top(text, key):
    """Removes a top-level `key = …` line (before the first table)."""
    lines, spans = tables(text)
    first = spans[0][0] if spans else len(lines)
    out = [l for i, l in enumerate(lines) if not (i < first and re.match(rf"^\s*{re.escape(key)}\s*=", l))]
    assert len(out) == len(lines) - 1, key
    return "\n".join(out)


def vehicle(i, x):
    return (f'\n[[vehicles]]\nid = "v{i}"\nkind = "auv"\nstart = [{x}, 100.0, 1000.0]\n'
            f'goal = [{x}, 1900.0, 1000.0]\nspeed_min_mps = 0.5\nspeed_max_mps = 1.5\n'
            'max_turn_deg = 35.0\nmax_pitch_deg = 20.0\n')


def obstacle(i):
    return (f'\n[[obstacles]]\nid = "S{i}"\nkind = "soft"\ncentre = [{50 + i % 1900}.0, 1000.0, 1000.0]\n'
            'radius_m = 1.0\ninflation_m = 0.0\n')


NO_SEABED = lambda t: drop_tables(drop_tables(t, "[seabed"), "[[seabed")
SEABED_GRID = lambda path: lambda t: NO_SEABED(t) + f'\n[seabed.grid]\nfile = "{path}"\n'
CURRENT_GRID = lambda path: lambda t: set_key(
    del_key(t, "[currents]", "surface_velocity_mps"), "[currents]", "model", '"grid"'
) .replace('model = "grid"', f'model = "grid"\nfile = "{path}"')
S = lambda header, key, value, nth=0: lambda t: set_key(t, header, key, value, nth)
D = lambda header, key, nth=0: lambda t: del_key(t, header, key, nth)
A = lambda extra: lambda t: t.rstrip("\n") + "\n" + extra
V, O, C, I, F = "[[vehicles]]", "[optimizer]", "[coverage.planner]", "[inspection]", "[fleet]"

# (file stem, base scenario, edit, expectation, what the error must name)
CASES = [
    # --- optimizer budgets (amp-pso-1) ---
    ("particles-1e9", "amp-pso-1", S(O, "particles", "1000000000"), "error", "optimizer.particles"),
    ("populations-1e9", "amp-pso-1", S(O, "populations", "1000000000"), "error", "optimizer.populations"),
    ("iterations-1e12", "amp-pso-1", S(O, "iterations", "1000000000000"), "error", "optimizer.iterations"),
    ("waypoints-1e6", "amp-pso-1", S(O, "waypoints", "1000000"), "error", "optimizer.waypoints"),
    ("leader-particles-1e9", "amp-pso-1", S(O, "leader_particles", "1000000000"), "error", "optimizer.leader_particles"),
    ("threads-1e6", "amp-pso-1", S(O, "threads", "1000000"), "error", "optimizer.threads"),
    ("evaluations-product", "amp-pso-1", lambda t: S(O, "iterations", "1000000")(S(O, "particles", "10000")(t)), "error", "MAX_EVALUATIONS"),
    ("particles-zero", "amp-pso-1", S(O, "particles", "0"), "error", "optimizer.particles"),
    ("particles-negative", "amp-pso-1", S(O, "particles", "-5"), "error", "optimizer.particles"),
    ("particles-float", "amp-pso-1", S(O, "particles", "1e9"), "error", "optimizer.particles"),
    ("particles-string", "amp-pso-1", S(O, "particles", '"many"'), "error", "optimizer.particles"),
    ("iterations-nan", "amp-pso-1", S(O, "iterations", "nan"), "error", "optimizer.iterations"),
    ("seed-over-i64", "amp-pso-1", S(O, "seed", "18446744073709551615"), "error", "seed"),
    ("seed-negative", "amp-pso-1", S(O, "seed", "-1"), "error", "optimizer.seed"),
    ("weights-nan", "amp-pso-1", S(O, "weights", "[nan, 0.1, 0.3, 0.1, 0.3]"), "error", "optimizer.weights[0]"),
    ("weights-short", "amp-pso-1", S(O, "weights", "[0.2, 0.1]"), "error", "optimizer.weights"),
    ("penalty-inf", "amp-pso-1", S(O, "penalty_weight", "inf"), "error", "optimizer.penalty_weight"),
    ("velocity-fraction-1e300", "amp-pso-1", S(O, "max_velocity_fraction", "1e300"), "error", "optimizer.max_velocity_fraction"),
    ("algorithm-unknown", "amp-pso-1", S(O, "algorithm", '"quantum-pso"'), "error", "optimizer.algorithm"),
    ("agent-populations-1e9", "amp-pso-1", S("[optimizer.distributed]", "agent_populations", "1000000000"), "error", "optimizer.distributed.agent_populations"),
    ("unknown-key", "amp-pso-1", S(O, "partikles", "50"), "error", "partikles"),
    # --- vehicles ---
    ("vehicles-257", "amp-pso-1", A("".join(vehicle(i, 10.0 + 7.0 * i) for i in range(255))), "error", "vehicles"),
    ("vehicles-empty", "amp-pso-1", lambda t: drop_tables(t, "[[vehicles"), "error", "vehicles"),
    ("vehicle-duplicate-id", "amp-pso-1", S(V, "id", '"auv1"', 1), "error", "vehicles[1].id"),
    ("vehicle-id-slash", "amp-pso-1", S(V, "id", '"../etc"'), "error", "vehicles[0].id"),
    ("vehicle-id-empty", "amp-pso-1", S(V, "id", '""'), "error", "vehicles[0].id"),
    ("vehicle-kind-unknown", "amp-pso-1", S(V, "kind", '"submarine"'), "error", "kind"),
    ("start-equals-goal", "amp-pso-1", S(V, "goal", "[100.0, 300.0, 1600.0]"), "error", "vehicles[0].goal"),
    ("start-outside-bounds", "amp-pso-1", S(V, "start", "[-5000.0, 300.0, 1600.0]"), "error", "vehicles[0].start"),
    ("start-nan", "amp-pso-1", S(V, "start", "[nan, 300.0, 1600.0]"), "error", "vehicles[0].start"),
    ("start-two-coordinates", "amp-pso-1", S(V, "start", "[100.0, 300.0]"), "error", "start"),
    ("goal-in-hard-obstacle", "amp-pso-1", S(V, "goal", "[1000.0, 1000.0, 1000.0]"), "error", "vehicles[0].goal"),
    ("speed-1e-300", "amp-pso-1", S(V, "speed_min_mps", "1e-300"), "error", "vehicles[0].speed_min_mps"),
    ("speed-1e300", "amp-pso-1", S(V, "speed_max_mps", "1e300"), "error", "vehicles[0].speed_max_mps"),
    ("speed-zero", "amp-pso-1", S(V, "speed_min_mps", "0.0"), "error", "vehicles[0].speed_min_mps"),
    ("speed-negative", "amp-pso-1", S(V, "speed_max_mps", "-1.0"), "error", "vehicles[0].speed_max_mps"),
    ("speed-inf", "amp-pso-1", S(V, "speed_max_mps", "inf"), "error", "vehicles[0].speed_max_mps"),
    ("speed-max-under-min", "amp-pso-1", S(V, "speed_max_mps", "0.1"), "error", "vehicles[0].speed_max_mps"),
    ("speed-missing", "amp-pso-1", D(V, "speed_max_mps"), "error", "speed_max_mps"),
    ("turn-zero", "amp-pso-1", S(V, "max_turn_deg", "0.0"), "error", "vehicles[0].max_turn_deg"),
    ("turn-720", "amp-pso-1", S(V, "max_turn_deg", "720.0"), "error", "vehicles[0].max_turn_deg"),
    ("turn-nan", "amp-pso-1", S(V, "max_turn_deg", "nan"), "error", "vehicles[0].max_turn_deg"),
    ("pitch-91", "amp-pso-1", S(V, "max_pitch_deg", "91.0"), "error", "vehicles[0].max_pitch_deg"),
    ("pitch-negative", "amp-pso-1", S(V, "max_pitch_deg", "-20.0"), "error", "vehicles[0].max_pitch_deg"),
    ("turn-radius-zero", "amp-pso-1", S(V, "turn_radius_m", "0.0"), "error", "vehicles[0].turn_radius_m"),
    # --- bounds, obstacles, fleet ---
    ("bounds-inverted", "amp-pso-1", S("[bounds]", "max", "[-1.0, 2000.0, 2000.0]"), "error", "bounds.max[0]"),
    ("bounds-inf", "amp-pso-1", S("[bounds]", "max", "[inf, 2000.0, 2000.0]"), "error", "bounds.max[0]"),
    ("bounds-1e300", "amp-pso-1", S("[bounds]", "max", "[1e300, 2000.0, 2000.0]"), "error", "bounds.max[0]"),
    ("bounds-missing", "amp-pso-1", lambda t: drop_tables(t, "[bounds"), "error", "bounds"),
    ("obstacle-radius-1e300", "amp-pso-1", S("[[obstacles]]", "radius_m", "1e300", 1), "error", "obstacles[1].radius_m"),
    ("obstacle-radius-negative", "amp-pso-1", S("[[obstacles]]", "radius_m", "-300.0"), "error", "obstacles[0].radius_m"),
    ("obstacle-inflation-nan", "amp-pso-1", S("[[obstacles]]", "inflation_m", "nan"), "error", "obstacles[0].inflation_m"),
    ("obstacle-kind-unknown", "amp-pso-1", S("[[obstacles]]", "kind", '"lava"'), "error", "kind"),
    ("obstacles-1001", "amp-pso-1", A("".join(obstacle(i) for i in range(998))), "error", "obstacles"),
    ("d-min-negative", "amp-pso-1", S(F, "d_min_m", "-50.0"), "error", "fleet.d_min_m"),
    ("d-min-1e300", "amp-pso-1", S(F, "d_min_m", "1e300"), "error", "fleet.d_min_m"),
    ("mission-time-zero", "amp-pso-1", S(F, "mission_time_s", "0.0"), "error", "fleet.mission_time_s"),
    ("mission-time-1e300", "amp-pso-1", S(F, "mission_time_s", "1e300"), "error", "fleet.mission_time_s"),
    ("mission-time-missing", "amp-pso-1", D(F, "mission_time_s"), "error", "mission_time_s"),
    ("name-missing", "amp-pso-1", lambda t: drop_top(t, "name"), "error", "name"),
    ("syntax-error", "amp-pso-1", A("this is = = not toml\n"), "error", "line"),
    # --- the same kind of file with values that are odd but plannable ---
    ("plannable-no-obstacles", "amp-pso-1", lambda t: drop_tables(t, "[[obstacles"), "plan", ""),
    ("plannable-d-min-zero", "amp-pso-1", S(F, "d_min_m", "0.0"), "plan", ""),
    ("plannable-mission-time-1s", "amp-pso-1", S(F, "mission_time_s", "1.0"), "plan", ""),
    ("plannable-one-waypoint", "amp-pso-1", S(O, "waypoints", "1"), "plan", ""),
    ("plannable-seed-max-i64", "amp-pso-1", S(O, "seed", "9223372036854775807"), "plan", ""),
    ("plannable-weights-zero", "amp-pso-1", S(O, "weights", "[0.0, 0.0, 0.0, 0.0, 0.0]"), "plan", ""),
    ("plannable-speed-min-equals-max", "amp-pso-1", S(V, "speed_min_mps", "1.543333"), "plan", ""),
    ("plannable-turn-180", "amp-pso-1", S(V, "max_turn_deg", "180.0"), "plan", ""),
    ("plannable-unicode-name", "amp-pso-1", lambda t: t.replace('name = "amp-pso-1"', 'name = "ämp-pšo ☂"'), "plan", ""),
    ("plannable-pso-one-particle", "amp-pso-1", lambda t: S(O, "algorithm", '"pso"')(S(O, "particles", "1")(t)), "plan", ""),
    # --- crawler (ipso-dsmv): seabed, hazards, crawler settings, grid files ---
    ("crawler-samples-1e12", "ipso-dsmv", S("[crawler]", "samples", "1000000000000"), "error", "crawler.samples"),
    ("crawler-samples-3", "ipso-dsmv", S("[crawler]", "samples", "3"), "error", "crawler.samples"),
    ("crawler-mining-share-1", "ipso-dsmv", S("[crawler]", "mining_share", "1.0"), "error", "crawler.mining_share"),
    ("crawler-no-seabed", "ipso-dsmv", NO_SEABED, "error", "vehicles[0].kind"),
    ("hazard-radius-nan", "ipso-dsmv", S("[[hazards]]", "radius_m", "nan"), "error", "hazards[0].radius_m"),
    ("hazard-duplicate-start", "ipso-dsmv", S("[[hazards]]", "centre", "[1.0, 1.0]"), "error", "vehicles[0].start"),
    ("mountain-spread-zero", "ipso-dsmv", S("[[seabed.mountains]]", "spread_m", "[0.0, 12.0]"), "error", "seabed.mountains[0].spread_m"),
    ("relief-scale-1e-300", "ipso-dsmv", S("[seabed.relief]", "length_scale_m", "-1e-300"), "error", "seabed.relief.length_scale_m"),
    ("seabed-grid-dev-zero", "ipso-dsmv", SEABED_GRID("/dev/zero"), "error", "seabed.grid.file"),
    ("seabed-grid-etc-passwd", "ipso-dsmv", SEABED_GRID("/etc/passwd"), "error", "seabed.grid.file"),
    ("seabed-grid-directory", "ipso-dsmv", SEABED_GRID("/etc"), "error", "seabed.grid.file"),
    ("seabed-grid-missing-file", "ipso-dsmv", SEABED_GRID("no-such-grid.asc"), "error", "seabed.grid.file"),
    ("plannable-crawler-samples-4", "ipso-dsmv", S("[crawler]", "samples", "4"), "plan", ""),
    # --- energy (epa-pso): currents and the energy table ---
    ("current-1e300", "epa-pso", S("[currents]", "surface_velocity_mps", "[1e300, 0.0]"), "error", "currents.surface_velocity_mps"),
    ("current-nan", "epa-pso", S("[currents]", "surface_velocity_mps", "[nan, 0.0]"), "error", "currents.surface_velocity_mps"),
    ("current-grid-dev-zero", "epa-pso", CURRENT_GRID("/dev/zero"), "error", "currents.file"),
    ("current-grid-etc-passwd", "epa-pso", CURRENT_GRID("/etc/passwd"), "error", "currents.file"),
    ("energy-path-points-1e9", "epa-pso", S("[energy]", "path_points", "1000000000"), "error", "energy.path_points"),
    ("energy-control-points-zero", "epa-pso", S("[energy]", "control_points", "0"), "error", "energy.control_points"),
    ("energy-ground-speed-1e-300", "epa-pso", S("[energy]", "ground_speed_mps", "1e-300"), "error", "energy.ground_speed_mps"),
    ("energy-turn-radius-inf", "epa-pso", S("[energy]", "min_turn_radius_m", "inf"), "error", "energy.min_turn_radius_m"),
    ("energy-two-vehicles", "epa-pso", A(vehicle(2, 50.0).replace("100.0, 1000.0", "10.0, 50.0").replace("1900.0, 1000.0", "90.0, 50.0")), "error", "optimizer.algorithm"),
    ("mountains-1001", "epa-pso", A("".join(f"\n[[seabed.mountains]]\ncentre = [{i % 100}.0, 50.0]\nheight_m = 1.0\nspread_m = [5.0, 5.0]\n" for i in range(991))), "error", "seabed.mountains"),
    # --- inspection tours (cages-a) ---
    ("inspection-order-particles-1e9", "cages-a", S(I, "order_particles", "1000000000"), "error", "inspection.order_particles"),
    ("inspection-order-iterations-1e12", "cages-a", S(I, "order_iterations", "1000000000000"), "error", "inspection.order_iterations"),
    ("inspection-standoff-zero", "cages-a", S(I, "standoff_m", "0.0"), "error", "inspection.standoff_m"),
    ("inspection-unknown-cage", "cages-a", S(I, "cages", '["Z9"]'), "error", "inspection.cages[0]"),
    ("inspection-no-cages", "cages-a", lambda t: drop_tables(t, "[[obstacles"), "error", "inspection.cages"),
    ("inspection-goal-not-start", "cages-a", S(V, "goal", "[10.0, 10.0, 10.0]"), "error", "vehicles[0].goal"),
    ("inspection-with-path-planner", "cages-a", S(O, "algorithm", '"amp-pso"'), "error", "optimizer.algorithm"),
    # --- coverage (cpp-seabed) ---
    ("coverage-check-step-1e-9", "cpp-seabed", S(C, "check_step_m", "1e-9"), "error", "coverage.planner.check_step_m"),
    ("coverage-check-step-zero", "cpp-seabed", S(C, "check_step_m", "0.0"), "error", "coverage.planner.check_step_m"),
    ("coverage-rollback-step-1e-9", "cpp-seabed", S(C, "rollback_step_m", "1e-9"), "error", "coverage.planner.rollback_step_m"),
    ("coverage-turn-radius-1e-6", "cpp-seabed", lambda t: S(C, "check_step_m", "1e-6")(S(C, "min_turn_radius_m", "1e-6")(t)), "error", "coverage.planner.check_step_m"),
    ("coverage-width-zero", "cpp-seabed", S("[coverage.limits]", "vehicle_width_m", "0.0"), "error", "coverage.limits.vehicle_width_m"),
    ("coverage-width-100", "cpp-seabed", S("[coverage.limits]", "vehicle_width_m", "100.0"), "error", "coverage.limits.vehicle_width_m"),
    ("coverage-width-5000", "cpp-seabed", S("[coverage.limits]", "vehicle_width_m", "5000.0"), "error", "coverage.limits.vehicle_width_m"),
    ("coverage-width-over-clearance", "cpp-seabed", S("[coverage.limits]", "vehicle_width_m", "20.0"), "error", "coverage.planner.safety_clearance_m"),
    ("coverage-cell-1e-3", "cpp-seabed", S("[coverage.terrain]", "cell_m", "0.001"), "error", "coverage.terrain.cell_m"),
    ("coverage-size-1e300", "cpp-seabed", S("[coverage.terrain]", "size_m", "[1e300, 1e300]"), "error", "coverage.terrain.cell_m"),
    ("coverage-slope-90", "cpp-seabed", S("[coverage.limits]", "critical_slope_deg", "90.0"), "error", "coverage.limits.critical_slope_deg"),
    ("coverage-peaks-1e9", "cpp-seabed", S("[coverage.terrain.random_peaks]", "count", "1000000000"), "error", "coverage.terrain.random_peaks"),
    ("coverage-octaves-1000", "cpp-seabed", S("[coverage.terrain.undulation]", "octaves", "1000"), "error", "coverage.terrain.undulation.octaves"),
    ("coverage-transit-budget-1e18", "cpp-seabed", S(C, "transit_budget", "1000000000000000000"), "error", "coverage.planner.transit_budget"),
    ("coverage-tracking-speed-1e-300", "cpp-seabed", S("[coverage.tracking]", "speed_mps", "1e-300"), "error", "coverage.tracking"),
    ("coverage-heightmap-dev-zero", "cpp-seabed", S("[coverage]", "heightmap", '"/dev/zero"'), "error", "coverage.heightmap"),
    ("coverage-heightmap-directory", "cpp-seabed", S("[coverage]", "heightmap", '"/etc"'), "error", "coverage.heightmap"),
    ("coverage-heightmap-etc-passwd", "cpp-seabed", S("[coverage]", "heightmap", '"/etc/passwd"'), "plan-error", "/etc/passwd"),
]


def main():
    OUT.mkdir(parents=True, exist_ok=True)
    for old in OUT.glob("*.toml"):
        old.unlink()
    manifest = ["# file\texpect\tnames (see make_scenarios.py)"]
    seen = set()
    for stem, base, edit, expect, names in CASES:
        assert stem not in seen, stem
        seen.add(stem)
        text = (ROOT / "scenarios" / f"{base}.toml").read_text()
        hostile = edit(text)
        assert hostile != text, stem
        header = f"# Hostile: scenarios/{base}.toml with one change ({stem}); expect {expect} {names}\n"
        (OUT / f"{stem}.toml").write_text(header + hostile)
        manifest.append(f"{stem}.toml\t{expect}\t{names or '-'}")
    (OUT / "manifest.tsv").write_text("\n".join(manifest) + "\n")
    print(f"wrote {len(CASES)} files to {OUT}")


if __name__ == "__main__":
    main()
