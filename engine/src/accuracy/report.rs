//! What the measurements say: fitted convergence slopes, the Pareto front
//! of error against time, the best setting for each time budget, bias
//! flags, and the CSV and Markdown files that carry them.

use super::Report;
use super::sweep::{Curve, Measurement};
use std::fmt::Write;

/// Least-squares slope of ln y against ln x (`None` with fewer than two
/// distinct positive points).
pub fn log_log_slope(points: impl IntoIterator<Item = (f64, f64)>) -> Option<f64> {
    let pts: Vec<(f64, f64)> = points
        .into_iter()
        .filter(|(x, y)| *x > 0.0 && *y > 0.0)
        .map(|(x, y)| (x.ln(), y.ln()))
        .collect();
    let n = pts.len() as f64;
    let mx = pts.iter().map(|p| p.0).sum::<f64>() / n;
    let my = pts.iter().map(|p| p.1).sum::<f64>() / n;
    let sxx: f64 = pts.iter().map(|p| (p.0 - mx).powi(2)).sum();
    let sxy: f64 = pts.iter().map(|p| (p.0 - mx) * (p.1 - my)).sum();
    (pts.len() >= 2 && sxx > 0.0).then(|| sxy / sxx)
}

impl Measurement {
    /// The RMSE with the reference's own noise taken out:
    /// √(MSE − Var(reference)) = √(bias² + variance).
    pub fn own_rmse(&self) -> f64 {
        (self.bias.bias2 + self.bias.variance).max(0.0).sqrt()
    }
}

impl Curve {
    /// Slope of log [`own_rmse`](Measurement::own_rmse) against log time
    /// (−0.5 for an unbiased setting whose time is proportional to its
    /// samples).
    pub fn slope_time(&self) -> Option<f64> {
        log_log_slope(self.points.iter().map(|p| (p.time, p.own_rmse())))
    }

    /// Slope of log [`own_rmse`](Measurement::own_rmse) against log spp
    /// (−0.5 for an unbiased setting with independent samples; steeper for
    /// good stratification).
    pub fn slope_spp(&self) -> Option<f64> {
        log_log_slope(self.points.iter().map(|p| (p.spp as f64, p.own_rmse())))
    }

    /// The last measurement.
    pub fn last(&self) -> Option<&Measurement> {
        self.points.last()
    }

    /// Whether the last measurement shows bias beyond its noise (see
    /// [`BiasSplit::is_biased`](super::metrics::BiasSplit::is_biased)).
    pub fn is_biased(&self) -> bool {
        self.last().is_some_and(|m| m.bias.is_biased())
    }

    /// RMSE at time `t`, interpolated log-log between measurements; `None`
    /// outside the measured times.
    pub fn rmse_at(&self, t: f64) -> Option<f64> {
        let i = self.points.iter().position(|p| p.time >= t)?;
        let b = &self.points[i];
        if b.time == t {
            return Some(b.metrics.rmse);
        }
        let a = self.points.get(i.checked_sub(1)?)?;
        let f = (t / a.time).ln() / (b.time / a.time).ln();
        Some((a.metrics.rmse.ln() * (1.0 - f) + b.metrics.rmse.ln() * f).exp())
    }

    /// Time to reach an RMSE of `target`, interpolated log-log; `None` if it
    /// was not reached.
    pub fn time_to(&self, target: f64) -> Option<f64> {
        let i = self.points.iter().position(|p| p.metrics.rmse <= target)?;
        let b = &self.points[i];
        let Some(a) = i.checked_sub(1).map(|j| &self.points[j]) else {
            return Some(b.time);
        };
        let f = (target / a.metrics.rmse).ln() / (b.metrics.rmse / a.metrics.rmse).ln();
        Some((a.time.ln() * (1.0 - f) + b.time.ln() * f).exp())
    }
}

/// The measurements no other measurement beats in both time and RMSE, as
/// (curve, point) indices by increasing time.
pub fn pareto_front(curves: &[Curve]) -> Vec<(usize, usize)> {
    let mut all: Vec<(usize, usize)> = curves
        .iter()
        .enumerate()
        .flat_map(|(c, curve)| (0..curve.points.len()).map(move |p| (c, p)))
        .collect();
    let at = |&(c, p): &(usize, usize)| &curves[c].points[p];
    all.sort_by(|a, b| {
        at(a)
            .time
            .total_cmp(&at(b).time)
            .then(at(a).metrics.rmse.total_cmp(&at(b).metrics.rmse))
    });
    let mut front = Vec::new();
    let mut best = f64::INFINITY;
    for i in all {
        if at(&i).metrics.rmse < best {
            best = at(&i).metrics.rmse;
            front.push(i);
        }
    }
    front
}

/// The measurement with the lowest RMSE among those done within `t`
/// seconds, as (curve, point) indices.
pub fn best_within(curves: &[Curve], t: f64) -> Option<(usize, usize)> {
    curves
        .iter()
        .enumerate()
        .flat_map(|(c, curve)| curve.points.iter().enumerate().map(move |(p, m)| (c, p, m)))
        .filter(|(_, _, m)| m.time <= t)
        .min_by(|a, b| a.2.metrics.rmse.total_cmp(&b.2.metrics.rmse))
        .map(|(c, p, _)| (c, p))
}

/// The CSV header; [`csv`] writes one row per measurement in this order.
pub const CSV_HEADER: &str = "setting,axis,value,spp,time_s,rmse,rel_mse,mae,flip,variance,bias2,bias_z2,bias_threshold,bias_share,biased,pareto";

/// Every measurement as CSV (labels contain no commas or quotes).
pub fn csv(report: &Report) -> String {
    let front = pareto_front(&report.curves);
    let mut out = String::from(CSV_HEADER);
    out.push('\n');
    for (c, curve) in report.curves.iter().enumerate() {
        let s = &curve.setting;
        for (p, m) in curve.points.iter().enumerate() {
            let _ = writeln!(
                out,
                "{},{},{},{},{:.6},{:.6e},{:.6e},{:.6e},{:.6e},{:.6e},{:.6e},{:.4},{:.4},{:.4},{},{}",
                s.label(),
                s.axis,
                s.value(),
                m.spp,
                m.time,
                m.metrics.rmse,
                m.metrics.rel_mse,
                m.metrics.mae,
                m.metrics.flip,
                m.bias.variance,
                m.bias.bias2,
                m.bias.block_z2,
                m.bias.threshold,
                m.bias.bias_share(),
                m.bias.is_biased(),
                front.contains(&(c, p)),
            );
        }
    }
    out
}

fn opt(v: Option<f64>, f: impl Fn(f64) -> String) -> String {
    v.map_or_else(|| "–".to_string(), f)
}

/// The Markdown summary: reference, best setting per time budget, a table
/// of every setting, time to reach given errors, and bias flags.
pub fn summary(report: &Report) -> String {
    let curves = &report.curves;
    let mut md = String::new();
    let _ = writeln!(md, "# Accuracy and time: {}\n", report.scene.display());
    let r = &report.reference;
    let _ = match (r.spp, r.time, r.relative_error()) {
        (Some(spp), Some(t), Some(e)) => writeln!(
            md,
            "Reference: rendered here, {spp} spp in {:.1} s; relative standard error {:.3} % \
             (RMS noise over mean value, from its two seed halves). Its noise is subtracted \
             in the bias estimates.",
            t.as_secs_f64(),
            100.0 * e
        ),
        _ => writeln!(
            md,
            "Reference: read from a file; its noise is unknown and taken as zero."
        ),
    };
    let _ = writeln!(
        md,
        "Sweep: {} settings in {:.1} s ({:.1} s with the reference; budget {:.1} s for both), \
         CPU backend (`backend=gpu`: the GPU backend), {}×{} pixels. Time is extract (BVH build \
         included) plus rendering, measured on this machine.\n",
        curves.len(),
        report.sweep_time.as_secs_f64(),
        report.total_time.as_secs_f64(),
        report.budget.as_secs_f64(),
        r.image.width,
        r.image.height
    );

    let _ = writeln!(md, "## Best setting for each time budget\n");
    let _ = writeln!(
        md,
        "| time budget | lowest RMSE | spp | RMSE | FLIP |\n| --- | --- | --- | --- | --- |"
    );
    let first = curves
        .iter()
        .filter_map(|c| c.points.first())
        .map(|m| m.time)
        .fold(f64::INFINITY, f64::min);
    let last = curves
        .iter()
        .filter_map(|c| c.last())
        .map(|m| m.time)
        .fold(0.0, f64::max);
    if first.is_finite() && last > 0.0 {
        let steps = 5;
        for k in 0..steps {
            let t = first * (last / first).powf(k as f64 / (steps - 1) as f64);
            if let Some((c, p)) = best_within(curves, t * (1.0 + 1e-9)) {
                let m = &curves[c].points[p];
                let flag = if curves[c].is_biased() {
                    " (biased)"
                } else {
                    ""
                };
                let _ = writeln!(
                    md,
                    "| {t:.3} s | {}{flag} | {} | {:.4e} | {:.4} |",
                    curves[c].setting.label(),
                    m.spp,
                    m.metrics.rmse,
                    m.metrics.flip
                );
            }
        }
    }

    let equal_time = curves
        .iter()
        .filter_map(|c| c.last())
        .map(|m| m.time)
        .fold(f64::INFINITY, f64::min);
    let _ = writeln!(md, "\n## Settings\n");
    let _ = writeln!(
        md,
        "Last measurement of each setting; RMSE at equal time is at {equal_time:.3} s, the \
         time every setting reached. Slopes are of log RMSE against log time and log spp \
         (−0.5: unbiased Monte Carlo; the reference's noise taken out). z² is the mean square of \
         the block-mean differences from the reference over that of the block-mean half \
         differences (what noise alone gives): ≈ 1 unbiased, flagged above its threshold \
         (from the effective number of blocks; shown after the slash). Bias share is \
         1 − threshold/z², the part of the block-mean differences that noise cannot explain \
         (0 unless flagged).\n"
    );
    let _ = writeln!(
        md,
        "| setting | spp | time (s) | RMSE | relMSE | MAE | FLIP | RMSE at equal time | slope (time) | slope (spp) | bias share | z² | biased |\n\
         | --- | --- | --- | --- | --- | --- | --- | --- | --- | --- | --- | --- | --- |"
    );
    for c in curves {
        let Some(m) = c.last() else { continue };
        let _ = writeln!(
            md,
            "| {} | {} | {:.3} | {:.4e} | {:.4e} | {:.4e} | {:.4} | {} | {} | {} | {:.0} % | {:.2} / {:.2} | {} |",
            c.setting.label(),
            m.spp,
            m.time,
            m.metrics.rmse,
            m.metrics.rel_mse,
            m.metrics.mae,
            m.metrics.flip,
            opt(c.rmse_at(equal_time), |v| format!("{v:.4e}")),
            opt(c.slope_time(), |v| format!("{v:.2}")),
            opt(c.slope_spp(), |v| format!("{v:.2}")),
            100.0 * m.bias.bias_share(),
            m.bias.block_z2,
            m.bias.threshold,
            if c.is_biased() { "**yes**" } else { "no" }
        );
    }

    if let Some(target) = curves
        .first()
        .and_then(|c| c.last())
        .map(|m| m.metrics.rmse)
    {
        let levels = [4.0 * target, 2.0 * target, target];
        let _ = writeln!(md, "\n## Time to reach an RMSE\n");
        let _ = writeln!(
            md,
            "Levels are 4×, 2× and 1× the baseline's last RMSE; – means not reached.\n"
        );
        let _ = writeln!(
            md,
            "| setting | ≤ {:.3e} | ≤ {:.3e} | ≤ {:.3e} |\n| --- | --- | --- | --- |",
            levels[0], levels[1], levels[2]
        );
        for c in curves {
            let cells: Vec<String> = levels
                .iter()
                .map(|&l| opt(c.time_to(l), |t| format!("{t:.3} s")))
                .collect();
            let _ = writeln!(md, "| {} | {} |", c.setting.label(), cells.join(" | "));
        }
    }

    let biased: Vec<String> = curves
        .iter()
        .filter(|c| c.is_biased())
        .map(|c| format!("`{}`", c.setting.label()))
        .collect();
    let _ = writeln!(md, "\n## Notes\n");
    if biased.is_empty() {
        let _ = writeln!(md, "- No setting shows bias beyond its noise.");
    } else {
        let _ = writeln!(
            md,
            "- Biased against the reference (the scene as written): {}. Their error stops \
             falling once the noise is below the bias; filters and other changes that alter \
             the converged image count as bias too.",
            biased.join(", ")
        );
    }
    for c in curves.iter().filter(|c| c.invalid_samples > 0) {
        let _ = writeln!(
            md,
            "- `{}`: {} samples were NaN or infinite and were recorded as black.",
            c.setting.label(),
            c.invalid_samples
        );
    }
    for note in &report.notes {
        let _ = writeln!(md, "- {note}");
    }
    md
}

#[cfg(test)]
mod tests {
    // `unwrap` in this test code is the assertion: the inputs are the test's
    // own, so a failure is a bug, and the panic reports it with the error.
    use super::*;
    use crate::accuracy::Axis;
    use crate::accuracy::metrics::{BiasSplit, Metrics};
    use crate::accuracy::sweep::{Change, Setting};

    fn point(spp: u32, time: f64, rmse: f64) -> Measurement {
        Measurement {
            spp,
            time,
            metrics: Metrics {
                rmse,
                rel_mse: 0.0,
                mae: 0.0,
                flip: 0.0,
            },
            bias: BiasSplit {
                variance: rmse * rmse,
                bias2: 0.0,
                block_z2: 1.0,
                threshold: 2.0,
            },
        }
    }

    fn curve(depth: i32, points: &[(f64, f64)]) -> Curve {
        Curve {
            setting: Setting {
                axis: Axis::MaxDepth,
                change: Change::MaxDepth(depth),
            },
            setup: 0.0,
            points: points
                .iter()
                .enumerate()
                .map(|(i, &(t, e))| point(2 * 4u32.pow(i as u32), t, e))
                .collect(),
            invalid_samples: 0,
        }
    }

    #[test]
    fn slope_of_a_power_law_is_its_exponent() {
        let pts = (1..6).map(|k| (k as f64, 3.0 * (k as f64).powf(-0.5)));
        assert!((log_log_slope(pts).unwrap() + 0.5).abs() < 1e-12);
        assert_eq!(log_log_slope([(1.0, 1.0)]), None);
        assert_eq!(log_log_slope([(2.0, 1.0), (2.0, 3.0)]), None);
        let c = curve(2, &[(1.0, 1.0), (4.0, 0.5), (16.0, 0.25)]);
        assert!((c.slope_time().unwrap() + 0.5).abs() < 1e-12);
        assert!((c.slope_spp().unwrap() + 0.5).abs() < 1e-12);
    }

    #[test]
    fn interpolation_is_log_log_between_measurements() {
        let c = curve(2, &[(1.0, 1.0), (4.0, 0.5), (16.0, 0.25)]);
        assert!((c.rmse_at(2.0).unwrap() - 0.5f64.sqrt()).abs() < 1e-12);
        assert_eq!(c.rmse_at(4.0), Some(0.5));
        assert_eq!(c.rmse_at(0.5), None);
        assert_eq!(c.rmse_at(17.0), None);
        assert!((c.time_to(0.5f64.sqrt()).unwrap() - 2.0).abs() < 1e-12);
        assert_eq!(c.time_to(2.0), Some(1.0));
        assert_eq!(c.time_to(0.1), None);
    }

    #[test]
    fn pareto_front_keeps_what_nothing_beats() {
        let a = curve(2, &[(1.0, 1.0), (2.0, 0.8), (4.0, 0.7)]);
        let b = curve(3, &[(1.5, 0.9), (3.0, 0.5), (6.0, 0.6)]);
        let curves = [a, b];
        assert_eq!(pareto_front(&curves), [(0, 0), (1, 0), (0, 1), (1, 1)]);
        assert_eq!(best_within(&curves, 2.5), Some((0, 1)));
        assert_eq!(best_within(&curves, 10.0), Some((1, 1)));
        assert_eq!(best_within(&curves, 0.5), None);
    }

    #[test]
    fn bias_flag_follows_the_last_measurement() {
        let mut c = curve(2, &[(1.0, 1.0), (2.0, 0.9)]);
        assert!(!c.is_biased());
        c.points[1].bias.block_z2 = 3.0;
        assert!(c.is_biased());
        c.points[0].bias.block_z2 = 100.0;
        c.points[1].bias.block_z2 = 1.0;
        assert!(!c.is_biased());
    }
}
