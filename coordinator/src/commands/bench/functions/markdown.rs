//! The suite's report as markdown: Lu et al. 2023, Table 5 (best / mean / std, plus the worst run), the
//! runs that found f*, the runs the budget cut short, Table 6 (Wilcoxon rank-sum p-values of IPSO
//! against each other algorithm), evaluations per run and a legend.

use std::fmt::Write as _;

use shoal_common::stats;

use super::report::{Cell, FunctionInfo, Report, LATE_SHARE, MULTI_POPULATIONS};

/// A number for the tables: six significant digits between 10⁻³ and 10⁵ (so Branin's 0.397887
/// and Six-Hump Camel's −1.03163 read as in the paper), scientific otherwise.
pub fn number(v: f64) -> String {
    if v.is_nan() {
        "—".to_string()
    } else if v == 0.0 {
        "0".to_string()
    } else if (1e-3..1e5).contains(&v.abs()) {
        let decimals = (5 - v.abs().log10().floor() as i32).clamp(0, 8) as usize;
        format!("{v:.decimals$}")
    } else {
        format!("{v:.3e}")
    }
}

/// A p-value: three decimals, or two significant digits below 10⁻³.
fn p_value(p: f64) -> String {
    if p < 1e-3 {
        format!("{p:.1e}")
    } else {
        format!("{p:.3}")
    }
}

/// A statistic of a cell's values (best, mean, …).
type Statistic = fn(&[f64]) -> f64;

/// Absolute distance to f* under which a run counts as having found the optimum.
pub const HIT_TOLERANCE: f64 = 1e-4;

/// The report as markdown.
pub fn markdown(r: &Report) -> String {
    let mut s = String::new();
    let _ = write_markdown(&mut s, r);
    s
}

/// A table's header row and its rule: `first` (which may hold several columns) then `names`.
fn header(s: &mut String, first: &str, names: &[&str]) -> std::fmt::Result {
    writeln!(s, "| {first} | {} |", names.join(" | "))?;
    let columns = 1 + first.matches('|').count() + names.len();
    writeln!(s, "{}|", "|---".repeat(columns))
}

fn write_markdown(s: &mut String, r: &Report) -> std::fmt::Result {
    let scalable_dim = r.functions.iter().find(|f| f.scalable).map(|f| f.dim);
    writeln!(
        s,
        "## Best / mean / std of the best cost over {} runs (Lu et al. 2023, Table 5)\n",
        r.runs
    )?;
    writeln!(
        s,
        "M = {} particles, t_max = {} iterations{}, base seed {}, velocity cap {}. Lower is \
         better; f* is the function's known minimum. Bold: the lowest best and mean of the row.\n",
        r.particles,
        r.iterations,
        scalable_dim.map_or(String::new(), |d| format!(", D = {d} for f1–f8")),
        r.seed,
        r.velocity_cap.map_or_else(
            || "each solver's own (Zhi & Zuo's 0.1, the others' 0.2 of each range)".to_string(),
            |c| format!("{c} of each range for every solver")
        ),
    )?;
    if !r.complete {
        writeln!(
            s,
            "**Interrupted: only the runs that finished are counted.**\n"
        )?;
    }
    header(s, "function | statistic", &r.algorithms)?;
    for (fi, f) in r.functions.iter().enumerate() {
        let cells = &r.cells[fi];
        let rows: [(&str, Statistic, bool); 4] = [
            ("best", stats::min, true),
            ("mean", stats::mean, true),
            ("std", stats::sample_std, false),
            ("worst", stats::max, false),
        ];
        for (ri, (stat, func, bold)) in rows.iter().enumerate() {
            let texts: Vec<String> = cells.iter().map(|c| number(func(&c.values))).collect();
            let lowest = cells
                .iter()
                .map(|c| func(&c.values))
                .filter(|v| !v.is_nan())
                .reduce(f64::min)
                .map(number);
            let first = if ri == 0 {
                format!(
                    "{} {} (D = {}, f* = {})",
                    f.label,
                    f.name,
                    f.dim,
                    number(f.optimum)
                )
            } else {
                String::new()
            };
            let shown: Vec<String> = texts
                .into_iter()
                .map(|t| {
                    if *bold && lowest.as_ref() == Some(&t) {
                        format!("**{t}**")
                    } else {
                        t
                    }
                })
                .collect();
            writeln!(s, "| {first} | {stat} | {} |", shown.join(" | "))?;
        }
    }

    writeln!(
        s,
        "\n## Runs whose best is within {HIT_TOLERANCE:e} of f* (Hu et al. 2023, Table 2's \
         convergence rate)\n"
    )?;
    counts(s, r, |c, f| {
        let n = c
            .values
            .iter()
            .filter(|v| (**v - f.optimum).abs() <= HIT_TOLERANCE)
            .count();
        (n, c.values.len())
    })?;

    writeln!(
        s,
        "\n## Runs still improving over the last {:.0} % of the iterations\n\n\
         A run counts when its best fell by more than 1e-9 of max(1, |best|) over its last \
         {:.0} % of iterations: the budget, not the optimizer, ended it. Many here mean the \
         row's figures are limited by t_max.\n",
        LATE_SHARE * 100.0,
        LATE_SHARE * 100.0
    )?;
    counts(s, r, |c, _| {
        let n = c.still_improving.iter().filter(|l| **l).count();
        (n, c.still_improving.len())
    })?;

    write_wilcoxon(s, r)?;

    writeln!(s, "\n## Evaluations per run (mean)\n")?;
    header(s, "", &r.algorithms)?;
    let evals: Vec<String> = (0..r.algorithms.len())
        .map(|ai| {
            let all: Vec<f64> = r
                .cells
                .iter()
                .flat_map(|row| row[ai].evaluations.iter().map(|e| *e as f64))
                .collect();
            format!("{:.0}", stats::mean(&all))
        })
        .collect();
    writeln!(s, "| evaluations | {} |", evals.join(" | "))?;
    writeln!(s, "\n## Algorithms\n")?;
    for (name, about) in r.algorithms.iter().zip(&r.about) {
        writeln!(s, "- `{name}`: {about}.")?;
    }
    writeln!(
        s,
        "- Multi-population solvers: {MULTI_POPULATIONS} followers of ⌊M/6⌋ particles and a \
         leader with the rest (M = 30: 5 × 5 + 5), instead of Table 5's 20 × 50 + 20, so the \
         budget is comparable."
    )
}

/// A table of "k/n" per function and algorithm, `count` giving (k, n) for a cell.
fn counts(
    s: &mut String,
    r: &Report,
    count: impl Fn(&Cell, &FunctionInfo) -> (usize, usize),
) -> std::fmt::Result {
    header(s, "function", &r.algorithms)?;
    for (fi, f) in r.functions.iter().enumerate() {
        let row: Vec<String> = r.cells[fi]
            .iter()
            .map(|c| {
                let (k, n) = count(c, f);
                format!("{k}/{n}")
            })
            .collect();
        writeln!(s, "| {} {} | {} |", f.label, f.name, row.join(" | "))?;
    }
    Ok(())
}

fn write_wilcoxon(s: &mut String, r: &Report) -> std::fmt::Result {
    let Some(ipso) = r.algorithms.iter().position(|a| *a == "ipso") else {
        return writeln!(
            s,
            "\n(No Wilcoxon table: IPSO was not among the algorithms.)"
        );
    };
    let others: Vec<usize> = (0..r.algorithms.len()).filter(|a| *a != ipso).collect();
    if others.is_empty() {
        return Ok(());
    }
    let names: Vec<String> = others
        .iter()
        .map(|a| format!("IPSO vs {}", r.algorithms[*a]))
        .collect();
    let names: Vec<&str> = names.iter().map(String::as_str).collect();
    writeln!(
        s,
        "\n## Wilcoxon rank-sum p-values, IPSO against each other algorithm (Lu et al. 2023, Table 6)\n"
    )?;
    writeln!(
        s,
        "Per function: two-sided Wilcoxon rank-sum (Mann–Whitney U, normal approximation with \
         tie and continuity corrections) of IPSO's {n} best costs (one per run) against the other \
         algorithm's {n}. (+) IPSO ranks lower, i.e. better; (−) IPSO ranks higher, worse; (=) \
         neither (U at its mean, e.g. every value tied). Bold: p < 0.05.\n",
        n = r.runs
    )?;
    writeln!(s, "| function | {} |", names.join(" | "))?;
    writeln!(s, "{}|", "|---".repeat(1 + names.len()))?;
    let cell = |x: &[f64], y: &[f64]| match stats::rank_sum(x, y) {
        None => "—".to_string(),
        Some(t) => {
            // U below its mean n_x n_y / 2: IPSO's values tend to be the lower ones.
            let centre = x.len() as f64 * y.len() as f64 / 2.0;
            let sign = match t.u.total_cmp(&centre) {
                std::cmp::Ordering::Less => "+",
                std::cmp::Ordering::Greater => "−",
                std::cmp::Ordering::Equal => "=",
            };
            let p = p_value(t.p);
            if t.p < 0.05 {
                format!("**{p}** ({sign})")
            } else {
                format!("{p} ({sign})")
            }
        }
    };
    for (fi, f) in r.functions.iter().enumerate() {
        let row = &r.cells[fi];
        let ps: Vec<String> = others
            .iter()
            .map(|a| cell(&row[ipso].values, &row[*a].values))
            .collect();
        writeln!(s, "| {} {} | {} |", f.label, f.name, ps.join(" | "))?;
    }
    // Lu et al.'s own test: the best value of each of f1–f8, eight against eight.
    let scalable: Vec<usize> = (0..r.functions.len())
        .filter(|fi| r.functions[*fi].scalable)
        .collect();
    if scalable.is_empty() {
        return Ok(());
    }
    let bests = |a: usize| -> Vec<f64> {
        scalable
            .iter()
            .map(|fi| stats::min(&r.cells[*fi][a].values))
            .collect()
    };
    let mine = bests(ipso);
    let ps: Vec<String> = others.iter().map(|a| cell(&mine, &bests(*a))).collect();
    writeln!(
        s,
        "| best values of f1–f8 ({n} vs {n}, as Table 6) | {} |",
        ps.join(" | "),
        n = scalable.len()
    )?;
    let wins: Vec<String> = others
        .iter()
        .map(|a| {
            let theirs = bests(*a);
            let k = mine.iter().zip(&theirs).filter(|(m, t)| m < t).count();
            format!("{k}/{}", scalable.len())
        })
        .collect();
    writeln!(
        s,
        "| f1–f8 where IPSO's best is lower | {} |",
        wins.join(" | ")
    )?;
    writeln!(
        s,
        "\nThe \"best values of f1–f8\" row is Lu et al.'s Table 6 test: for each pair, the best \
         cost over the runs on each of f1–f8, IPSO's {n} against the other's {n}, ranked \
         together. It pools functions whose values differ by many orders of magnitude, so it \
         says little on its own; the per-function rows compare like with like.",
        n = scalable.len()
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn numbers_read_like_the_paper() {
        assert_eq!(number(0.397_887_357_729_738_4), "0.397887");
        assert_eq!(number(-1.031_628_453_489_876_8), "-1.03163");
        assert_eq!(number(-3.322_368), "-3.32237");
        assert_eq!(number(3.074_86e-4), "3.075e-4");
        assert_eq!(number(1234.5678), "1234.57");
        assert_eq!(number(2.5e7), "2.500e7");
        assert_eq!((number(0.0), number(f64::NAN)), ("0".into(), "—".into()));
    }

    fn report(values: [Vec<f64>; 2]) -> Report {
        let [a, b] = values;
        Report {
            runs: a.len(),
            particles: 30,
            iterations: 300,
            seed: 1,
            velocity_cap: None,
            functions: vec![FunctionInfo {
                key: "sphere".into(),
                label: "f1".into(),
                name: "Sphere".into(),
                dim: 30,
                optimum: 0.0,
                scalable: true,
            }],
            algorithms: vec!["ipso", "spso"],
            about: vec!["i", "s"],
            cells: vec![vec![
                Cell {
                    evaluations: vec![9030; a.len()],
                    still_improving: (0..a.len()).map(|i| i == 0).collect(),
                    values: a,
                },
                Cell {
                    evaluations: vec![9030; b.len()],
                    still_improving: vec![false; b.len()],
                    values: b,
                },
            ]],
            complete: true,
        }
    }

    #[test]
    fn tables_by_hand() {
        // IPSO (0, 1e-5, 2e-5) against SPSO (1, 2, 3): mean 1e-5, sample std 1e-5; every IPSO
        // value ranks below every SPSO value, U = 0, z = −(4.5 − 0.5)/√5.25, p = 0.0809.
        let md = markdown(&report([vec![0.0, 1e-5, 2e-5], vec![1.0, 2.0, 3.0]]));
        for row in [
            "| function | statistic | ipso | spso |\n|---|---|---|---|\n",
            "| f1 Sphere (D = 30, f* = 0) | best | **0** | 1.00000 |",
            "|  | mean | **1.000e-5** | 2.00000 |",
            "|  | std | 1.000e-5 | 1.00000 |",
            "|  | worst | 2.000e-5 | 3.00000 |",
            "| f1 Sphere | 3/3 | 0/3 |",
            "## Runs still improving over the last 10 % of the iterations",
            "| f1 Sphere | 1/3 | 0/3 |",
            "| function | IPSO vs spso |\n|---|---|\n",
            "| f1 Sphere | 0.081 (+) |",
            "| best values of f1–f8 (1 vs 1, as Table 6) | 1.000 (+) |",
            "| f1–f8 where IPSO's best is lower | 1/1 |",
            "| evaluations | 9030 | 9030 |",
        ] {
            assert!(md.contains(row), "missing {row:?} in\n{md}");
        }
        // All tied: "=".
        let md = markdown(&report([vec![0.0; 3], vec![0.0; 3]]));
        assert!(md.contains("| f1 Sphere | 1.000 (=) |"), "{md}");
    }
}
