//! Coverage scenarios shrunk for end-to-end tests.

use std::path::{Path, PathBuf};

use super::scenario;

/// `cpp-fleet.toml` with two crawlers on a 300 m × 300 m area with one seamount; `edit`
/// changes the text further.
pub fn small_fleet(dir: &Path, edit: &dyn Fn(String) -> String) -> std::io::Result<PathBuf> {
    let text = std::fs::read_to_string(scenario("cpp-fleet"))?;
    let third = text
        .find("[[vehicles]]\nid = \"crawler3\"")
        .unwrap_or(text.len());
    let fleet = text.find("[fleet]").unwrap_or(text.len());
    let text = format!("{}{}", &text[..third], &text[fleet.max(third)..])
        .replace("max = [1000.0, 1000.0, 0.0]", "max = [300.0, 300.0, 0.0]")
        .replace("goal = [995.0, 335.0, -6000.0]", "goal = [295.0, 145.0, -6000.0]")
        .replace("start = [5.0, 345.0, -6000.0]", "start = [5.0, 155.0, -6000.0]")
        .replace("goal = [995.0, 665.0, -6000.0]", "goal = [295.0, 295.0, -6000.0]")
        .replace("size_m = [1000.0, 1000.0]", "size_m = [300.0, 300.0]")
        .replace("count = 8 ", "count = 0 ")
        .replace("count = 4 ", "count = 0 ")
        .replace("track = true", "track = false")
        .replace(
            "[coverage.terrain.undulation]",
            "peaks = [{ centre = [150.0, 150.0], height_m = 40.0, sigma_m = 20.0 }]\n[coverage.terrain.undulation]",
        );
    let path = dir.join("cpp-fleet-small.toml");
    std::fs::write(&path, edit(text))?;
    Ok(path)
}
