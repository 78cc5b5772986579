//! The log-log fit: a power law y = c·x^slope through measured points, by least squares on
//! their logarithms (a study's MSE against its budget N).

use serde::Serialize;

/// A least-squares line through (log10 x, log10 y).
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct LogLogFit {
    /// d log y / d log x: −1 for error ∝ 1/N.
    pub slope: f64,
    /// log10 y at x = 1.
    pub intercept: f64,
}

/// Fits log10(y) = intercept + slope·log10(x) by least squares; points with y ≤ 0 are skipped.
/// Returns None with fewer than two usable points.
pub fn loglog_fit(points: &[(f64, f64)]) -> Option<LogLogFit> {
    let pts: Vec<(f64, f64)> = points
        .iter()
        .filter(|(x, y)| *x > 0.0 && *y > 0.0)
        .map(|(x, y)| (x.log10(), y.log10()))
        .collect();
    if pts.len() < 2 {
        return None;
    }
    let n = pts.len() as f64;
    let mx = pts.iter().map(|p| p.0).sum::<f64>() / n;
    let my = pts.iter().map(|p| p.1).sum::<f64>() / n;
    let sxx: f64 = pts.iter().map(|p| (p.0 - mx).powi(2)).sum();
    if sxx == 0.0 {
        return None;
    }
    let sxy: f64 = pts.iter().map(|p| (p.0 - mx) * (p.1 - my)).sum();
    let slope = sxy / sxx;
    Some(LogLogFit {
        slope,
        intercept: my - slope * mx,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn fit_recovers_a_power_law() {
        let pts: Vec<(f64, f64)> = [1.0, 4.0, 16.0, 64.0, 256.0]
            .iter()
            .map(|&n: &f64| (n, 0.3 * n.powf(-1.5)))
            .collect();
        let fit = loglog_fit(&pts).unwrap();
        assert!((fit.slope + 1.5).abs() < 1e-12, "{fit:?}");
        assert!((fit.intercept - 0.3f64.log10()).abs() < 1e-12);
        assert!(loglog_fit(&pts[..1]).is_none());
        assert!(loglog_fit(&[(4.0, 1.0), (4.0, 2.0)]).is_none());
    }
}
