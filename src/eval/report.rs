//! The aligned text report of [`Metrics`].

use super::metrics::{Metrics, PredictionReport, SurfaceReport};
use std::fmt::{self, Display, Formatter};

/// `value` with `digits` decimals, or `-` when absent.
fn opt(value: Option<f64>, digits: usize) -> String {
    value.map_or_else(|| "-".to_string(), |v| format!("{v:.digits$}"))
}

fn yes(b: bool) -> &'static str {
    if b {
        "yes"
    } else {
        "no"
    }
}

impl Metrics {
    fn fmt_summary(&self, f: &mut Formatter<'_>) -> fmt::Result {
        let (a, c, d, k) = (
            &self.accuracy,
            &self.completeness,
            &self.detection,
            &self.compactness,
        );
        writeln!(
            f,
            "accuracy (one-sided Hausdorff, predictions -> ground truth)"
        )?;
        writeln!(f, "  {:<22}{:>14}", "area samples", a.area_samples)?;
        writeln!(f, "  {:<22}{:>14}", "boundary samples", a.boundary_samples)?;
        writeln!(f, "  {:<22}{:>14.2} m^2", "sampled area", a.sampled_area)?;
        writeln!(f, "  {:<22}{:>14} m", "mean", opt(a.mean, 4))?;
        writeln!(f, "  {:<22}{:>14} m", "median", opt(a.median, 4))?;
        writeln!(f, "  {:<22}{:>14} m", "max", opt(a.max, 4))?;
        let tol = self.options.completeness_tolerance;
        writeln!(f, "completeness (within {tol} m)")?;
        writeln!(f, "  {:<22}{:>14.2} m^2", "observed area", c.observed_area)?;
        writeln!(f, "  {:<22}{:>14.2} m^2", "covered area", c.covered_area)?;
        writeln!(f, "  {:<22}{:>14.4}", "completeness", c.completeness)?;
        writeln!(f, "detection")?;
        let tp = format!("({} of {} predictions)", d.true_positives, d.predictions);
        writeln!(f, "  {:<22}{:>14.4}   {tp}", "precision", d.precision)?;
        let found = format!(
            "({} of {} eligible surfaces)",
            d.found_surfaces, d.eligible_surfaces
        );
        writeln!(f, "  {:<22}{:>14.4}   {found}", "recall", d.recall)?;
        writeln!(f, "  {:<22}{:>14.4}", "f1", d.f1)?;
        writeln!(f, "duplicates")?;
        writeln!(f, "  {:<22}{:>14}", "pairs", self.duplicates.count)?;
        for p in &self.duplicates.pairs {
            writeln!(
                f,
                "    #{} and #{}: overlap {:.2} m^2, angle {:.2} deg",
                p.first, p.second, p.overlap_area, p.angle_deg
            )?;
        }
        writeln!(f, "compactness")?;
        writeln!(f, "  {:<22}{:>14}", "polygons", k.polygons)?;
        writeln!(f, "  {:<22}{:>14}", "vertices", k.vertices)?;
        writeln!(f, "  {:<22}{:>14}", "polygon bytes", k.polygon_bytes)?;
        writeln!(f, "  {:<22}{:>14}", "input points", k.input_points)?;
        writeln!(f, "  {:<22}{:>14}", "input bytes", k.input_bytes)?;
        writeln!(f, "  {:<22}{:>14}", "bytes ratio", opt(k.ratio, 6))
    }
}

fn fmt_surfaces(f: &mut Formatter<'_>, surfaces: &[SurfaceReport]) -> fmt::Result {
    writeln!(
        f,
        "{:>10} {:>9} {:>13} {:>12} {:>8} {:>8} {:>5}  predictions",
        "surface", "points", "observed m^2", "completeness", "matched", "eligible", "found"
    )?;
    for s in surfaces {
        let preds: Vec<String> = s
            .matching_predictions
            .iter()
            .map(|i| i.to_string())
            .collect();
        writeln!(
            f,
            "{:>10} {:>9} {:>13.2} {:>12.4} {:>8.4} {:>8} {:>5}  {}",
            s.id,
            s.points,
            s.observed_area,
            s.completeness,
            s.matched_coverage,
            yes(s.eligible),
            yes(s.found),
            preds.join(",")
        )?;
    }
    Ok(())
}

fn fmt_predictions(f: &mut Formatter<'_>, predictions: &[PredictionReport]) -> fmt::Result {
    writeln!(
        f,
        "{:>10} {:>10} {:>8} {:>8} {:>8} {:>9} {:>9} {:>10} {:>6} {:>3}",
        "prediction",
        "area m^2",
        "vertices",
        "spacing",
        "samples",
        "mean m",
        "max m",
        "surface",
        "share",
        "TP"
    )?;
    for p in predictions {
        writeln!(
            f,
            "{:>10} {:>10.2} {:>8} {:>8.3} {:>8} {:>9} {:>9} {:>10} {:>6.3} {:>3}",
            p.index,
            p.area,
            p.vertices,
            p.spacing,
            p.samples,
            opt(p.mean_distance, 4),
            opt(p.max_distance, 4),
            p.surface.map_or_else(|| "-".to_string(), |s| s.to_string()),
            p.on_surface_share,
            yes(p.true_positive)
        )?;
    }
    Ok(())
}

impl Display for Metrics {
    fn fmt(&self, f: &mut Formatter<'_>) -> fmt::Result {
        self.fmt_summary(f)?;
        writeln!(f)?;
        fmt_surfaces(f, &self.surfaces)?;
        writeln!(f)?;
        fmt_predictions(f, &self.predictions)
    }
}
