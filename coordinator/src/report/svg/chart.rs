//! What every chart of `plan.svg` and the coverage pictures draws on.

use std::fmt::Display;

use plotters::backend::SVGBackend;
use plotters::coord::types::RangedCoordf64;
use plotters::prelude::*;

/// A plotters chart on an SVG backend with two f64 axes: what every panel draws on.
pub type Chart<'a, 'b> =
    ChartContext<'a, SVGBackend<'b>, Cartesian2d<RangedCoordf64, RangedCoordf64>>;

/// Turns a plotters error into an `anyhow` error saying what was being drawn.
pub fn fail<E: Display>(what: &'static str) -> impl FnOnce(E) -> anyhow::Error {
    move |e| anyhow::anyhow!("svg: cannot draw {what}: {e}")
}
