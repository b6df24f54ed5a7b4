//! `shoal-coordinator export`: a plan for map tools (GeoJSON) or a ground station
//! (QGroundControl `.plan` files), or a mission log for robotics tools (MCAP). For a plan it
//! reads `plan.json` and the scenario, settles the geodetic origin and writes the files; the
//! conversions are in [`crate::report::geo_export`]. For a log it reads `mission.ndjson` (or an
//! MCAP log) and writes `mission.mcap` ([`crate::execute::log::mcap`]).

use std::path::{Path, PathBuf};

use anyhow::Context;
use shoal_common::geo::GeoOrigin;
use shoal_common::limits::{read_at_most, MAX_PLAN_BYTES};
use shoal_common::plan::Plan;
use shoal_common::scenario::Scenario;

use crate::execute::log;
use crate::report::geo_export::{self, geojson, qgc, ExportInput};

/// What to write.
#[derive(Debug, Clone, Copy, PartialEq, Eq, clap::ValueEnum)]
pub enum ExportFormat {
    /// `plan.geojson`: one RFC 7946 FeatureCollection.
    Geojson,
    /// `<vehicle>.plan`: one QGroundControl plan file per vehicle.
    Qgc,
    /// `mission.mcap`: a mission log (not a plan) as MCAP, as `run` writes it.
    Mcap,
}

/// `shoal-coordinator export`.
#[derive(Debug, Clone, clap::Args)]
pub struct ExportArgs {
    /// What to export: for geojson and qgc a plan (a plan.json, or the directory `plan` wrote
    /// one into); for mcap a mission log (`mission.ndjson` of `run`, or the directory `run`
    /// wrote it into).
    #[arg(env = "SHOAL_PLAN", value_name = "PLAN_OR_LOG")]
    pub plan: PathBuf,
    /// geojson (paths, waypoints, obstacles, bounds) or qgc (one mission per vehicle) of a
    /// plan; mcap (`mission.mcap`, for robotics tools such as Foxglove) of a mission log.
    #[arg(long, env = "SHOAL_EXPORT_FORMAT", value_enum)]
    pub format: ExportFormat,
    /// The scenario the plan was made for: obstacles, bounds, vehicle kinds and its `[origin]`.
    /// Without it only the paths are exported.
    #[arg(long, env = "SHOAL_SCENARIO")]
    pub scenario: Option<PathBuf>,
    /// Geodetic position of the scenario point (0, 0, 0): LAT,LON,ALT (degrees, metres above
    /// mean sea level), when neither the plan nor the scenario has one.
    #[arg(long, env = "SHOAL_ORIGIN", allow_hyphen_values = true)]
    pub origin: Option<GeoOrigin>,
    /// Directory for the files (created if missing).
    #[arg(long, env = "SHOAL_OUT")]
    pub out: PathBuf,
}

/// Runs `export`; exit status 0 when the files are written.
pub fn command(args: &ExportArgs) -> anyhow::Result<i32> {
    if args.format == ExportFormat::Mcap {
        return export_log(args);
    }
    let path = if args.plan.is_dir() {
        args.plan.join("plan.json")
    } else {
        args.plan.clone()
    };
    if looks_like_log(&path) {
        anyhow::bail!(
            "{} is a mission log, not a plan: geojson and qgc export a plan (plan.json); a log exports with --format mcap",
            path.display()
        );
    }
    let plan = read_plan(&path)?;
    let scenario = args.scenario.as_deref().map(Scenario::load).transpose()?;
    let origin = geo_export::resolve_origin(
        plan.origin,
        scenario.as_ref().and_then(|s| s.origin),
        args.origin,
    )
    .map_err(anyhow::Error::msg)?;
    geo_export::check(&plan, scenario.as_ref())
        .map_err(anyhow::Error::msg)
        .with_context(|| path.display().to_string())?;
    if scenario.is_none() {
        eprintln!(
            "note: no --scenario: exporting the vehicles' paths only (no obstacles, bounds or geofence)"
        );
    }
    std::fs::create_dir_all(&args.out)
        .with_context(|| format!("cannot create output directory {}", args.out.display()))?;
    let input = ExportInput {
        plan: &plan,
        origin,
        scenario: scenario.as_ref(),
    };
    let mut written = Vec::new();
    match args.format {
        ExportFormat::Geojson => {
            let file = args.out.join("plan.geojson");
            write_json(&file, &geojson::feature_collection(&input))?;
            written.push(file);
        }
        // Exported above, from a log.
        ExportFormat::Mcap => anyhow::bail!("a plan does not export to MCAP"),
        ExportFormat::Qgc => {
            for f in qgc::vehicle_files(&input) {
                let file = args.out.join(format!("{}.plan", f.vehicle));
                write_json(&file, &f.json)?;
                written.push(file);
                if !f.unfenced.is_empty() {
                    eprintln!(
                        "note: {}'s geofence leaves out hard obstacle(s) {}: its path passes over or under them",
                        f.vehicle,
                        f.unfenced.join(", ")
                    );
                }
            }
        }
    }
    for file in written {
        crate::report::out::say(&format!("Wrote {}\n", file.display()));
    }
    Ok(crate::commands::exit::EXIT_FEASIBLE)
}

/// `export --format mcap`: the mission log `args.plan` (NDJSON or MCAP) to `<out>/mission.mcap`.
fn export_log(args: &ExportArgs) -> anyhow::Result<i32> {
    let path = if args.plan.is_dir() {
        args.plan.join("mission.ndjson")
    } else {
        args.plan.clone()
    };
    if !looks_like_log(&path) {
        let hint = if read_plan(&path).is_ok() {
            "it is a plan; --format mcap exports a mission log (mission.ndjson of run), a plan exports with --format geojson or qgc"
        } else {
            "--format mcap exports a mission log (mission.ndjson of run)"
        };
        anyhow::bail!("{}: not a mission log: {hint}", path.display());
    }
    if args.scenario.is_some() || args.origin.is_some() {
        eprintln!("note: a mission log carries its scenario: --scenario and --origin are not used");
    }
    let log = log::read(&path)?;
    if let Some(cut) = log.cut_short {
        eprintln!(
            "note: {}: {cut}, the last, is cut short (the run stopped while writing it): left out",
            path.display()
        );
    }
    std::fs::create_dir_all(&args.out)
        .with_context(|| format!("cannot create output directory {}", args.out.display()))?;
    let file = args.out.join("mission.mcap");
    if same_file(&file, &path) {
        anyhow::bail!(
            "{} would be overwritten by its own export: choose another --out",
            path.display()
        );
    }
    log::mcap::write_all(&file, &log.records)?;
    crate::report::out::say(&format!(
        "Wrote {} ({} records)\n",
        file.display(),
        log.records.len()
    ));
    Ok(crate::commands::exit::EXIT_FEASIBLE)
}

/// Whether the file at `path` is a mission log: MCAP, or NDJSON whose first line is a record
/// (a plan.json starts otherwise). A file that cannot be read is not one.
fn looks_like_log(path: &Path) -> bool {
    use std::io::Read as _;
    let mut head = Vec::new();
    let read = std::fs::File::open(path).and_then(|f| f.take(16).read_to_end(&mut head));
    read.is_ok() && (head.starts_with(log::mcap::MAGIC) || head.starts_with(b"{\"record\":"))
}

/// Whether `a` and `b` name one existing file.
fn same_file(a: &Path, b: &Path) -> bool {
    match (a.canonicalize(), b.canonicalize()) {
        (Ok(a), Ok(b)) => a == b,
        _ => false,
    }
}

/// The plan at `path`, read within [`MAX_PLAN_BYTES`].
fn read_plan(path: &Path) -> anyhow::Result<Plan> {
    let text = read_at_most(path, MAX_PLAN_BYTES)
        .with_context(|| format!("{}: cannot read", path.display()))?;
    serde_json::from_str(&text).with_context(|| {
        format!(
            "{}: not a plan.json of paths (a coverage mission's plan is not exported)",
            path.display()
        )
    })
}

fn write_json(file: &Path, value: &serde_json::Value) -> anyhow::Result<()> {
    let text = serde_json::to_string_pretty(value).context("cannot serialise the export")?;
    std::fs::write(file, text).with_context(|| format!("cannot write {}", file.display()))
}
