//! The Pareto front of a panel (no other point is both cheaper and lower), and how this crate's
//! points stand against each peer's front; for the scaling panel, the cost at common sizes.

use crate::data::Case;
use crate::scenes::{Metric, Panel};

/// This crate's engine name in the lines.
pub const OURS: &str = "rapier_fvm";
/// Speed-up at equal or better accuracy that counts as clearly ahead.
const CLEAR_SPEEDUP: f64 = 5.0;

/// A case placed on a panel.
#[derive(Clone, Copy)]
pub struct Point<'a> {
    /// The case.
    pub case: &'a Case,
    /// Horizontal quantity (positive).
    pub x: f64,
    /// Vertical quantity (non-negative).
    pub y: f64,
}

/// The trusted cases of `cases` (see [`Case::trusted`]) the panel shows, with both quantities.
pub fn points<'a>(cases: &[&'a Case], panel: &Panel) -> Vec<Point<'a>> {
    cases
        .iter()
        .filter(|c| c.trusted() && panel.filter.accepts(c))
        .filter_map(|&case| {
            let (x, y) = (panel.x.of(case)?, panel.y.of(case)?);
            (x > 0.0 && y >= 0.0).then_some(Point { case, x, y })
        })
        .collect()
}

/// The non-dominated points (none other has both a lower or equal `x` and `y`, one of them
/// lower), in increasing `x`.
pub fn front<'a>(points: &[Point<'a>]) -> Vec<Point<'a>> {
    let mut sorted = points.to_vec();
    sorted.sort_by(|a, b| a.x.total_cmp(&b.x).then(a.y.total_cmp(&b.y)));
    let mut best = f64::INFINITY;
    sorted
        .into_iter()
        .filter(|p| {
            let keep = p.y < best;
            best = best.min(p.y);
            keep
        })
        .collect()
}

/// `v` with three significant digits.
pub fn sig(v: f64) -> String {
    if v == 0.0 || !v.is_finite() {
        return format!("{v}");
    }
    let digits = (2 - v.abs().log10().floor() as i32).max(0) as usize;
    format!("{v:.digits$}")
}

/// A quantity as the report prints it.
pub fn show(metric: Metric, v: f64) -> String {
    match metric {
        Metric::Ms => format!("{} ms", sig(v)),
        Metric::Elements => format!("{v:.0} tets"),
        Metric::AbsError => format!("{}%", sig(100.0 * v)),
        Metric::Abs("vertical_velocity_std") => format!("{} mm/s", sig(1e3 * v)),
        Metric::Abs(_) => format!("{} mm", sig(1e3 * v)),
    }
}

/// `engine case (y, x)`.
fn name(p: &Point, panel: &Panel) -> String {
    format!(
        "{} `{}` ({}, {})",
        p.case.engine,
        p.case.case,
        show(panel.y, p.y),
        show(panel.x, p.x)
    )
}

/// The summary of a trade-off panel: who is on the front, then this crate against each peer.
pub fn trade_off_summary(points: &[Point], panel: &Panel) -> Vec<String> {
    let all_front = front(points);
    let mut lines = vec![format!(
        "Pareto front: {}.",
        all_front
            .iter()
            .map(|p| name(p, panel))
            .collect::<Vec<_>>()
            .join("; ")
    )];
    let ours: Vec<Point> = points
        .iter()
        .copied()
        .filter(|p| p.case.engine == OURS)
        .collect();
    let mut peers: Vec<&str> = points
        .iter()
        .map(|p| p.case.engine.as_str())
        .filter(|&e| e != OURS)
        .collect();
    peers.sort_unstable();
    peers.dedup();
    for peer in peers {
        let theirs: Vec<Point> = points
            .iter()
            .copied()
            .filter(|p| p.case.engine == peer)
            .collect();
        lines.push(verdict(peer, &front(&theirs), &ours, panel));
    }
    lines
}

/// How this crate's points stand against one peer's front.
fn verdict(peer: &str, theirs: &[Point], ours: &[Point], panel: &Panel) -> String {
    if ours.is_empty() {
        return format!("vs {peer}: no stable {OURS} point.");
    }
    // Per front point of the peer: the fastest of ours at equal or lower y.
    let speedups: Vec<Option<f64>> = theirs
        .iter()
        .map(|q| {
            ours.iter()
                .filter(|p| p.y <= q.y)
                .map(|p| q.x / p.x)
                .fold(None, |best: Option<f64>, s| {
                    Some(best.map_or(s, |b| b.max(s)))
                })
        })
        .collect();
    let undominated: Vec<&Point> = theirs
        .iter()
        .zip(&speedups)
        .filter(|(_, s)| s.is_none_or(|s| s < 1.0))
        .map(|(q, _)| q)
        .collect();
    let known: Vec<f64> = speedups.iter().flatten().copied().collect();
    let range = || {
        let lo = known.iter().copied().fold(f64::INFINITY, f64::min);
        let hi = known.iter().copied().fold(0.0, f64::max);
        if sig(lo) == sig(hi) {
            format!("{}x", sig(lo))
        } else {
            format!("{}-{}x", sig(lo), sig(hi))
        }
    };
    let n = theirs.len();
    let points = if n == 1 {
        format!("the only point of {peer}'s front")
    } else {
        format!("each of the {n} points of {peer}'s front")
    };
    if undominated.is_empty() && known.iter().all(|&s| s >= CLEAR_SPEEDUP) {
        format!(
            "vs {peer}: **lower-left, at least {CLEAR_SPEEDUP}x**: at equal or lower {} {OURS} is {} faster than {points}.",
            y_name(panel),
            range()
        )
    } else if undominated.is_empty() {
        format!(
            "vs {peer}: **lower-left**: {points} is matched at equal or lower {} in less time ({} faster), though not everywhere by {CLEAR_SPEEDUP}x.",
            y_name(panel),
            range()
        )
    } else {
        let misses: Vec<String> = undominated.iter().map(|q| miss(q, ours, panel)).collect();
        let which = if n == 1 {
            format!("the only point of {peer}'s front is")
        } else {
            format!(
                "{} of the {n} points of {peer}'s front {}",
                undominated.len(),
                if undominated.len() == 1 { "is" } else { "are" }
            )
        };
        format!(
            "vs {peer}: **not lower-left**: {which} not matched at equal or lower {} in less time: {}",
            y_name(panel),
            misses.join(" ")
        )
    }
}

/// What `y` stands for in a sentence.
fn y_name(panel: &Panel) -> &'static str {
    match panel.y {
        Metric::AbsError => "error",
        Metric::Abs("vertical_velocity_std") => "jitter",
        Metric::Abs("penetration") => "penetration",
        _ => "value",
    }
}

/// A peer point none of ours dominates: our fastest as low, and our lowest as fast.
fn miss(q: &Point, ours: &[Point], panel: &Panel) -> String {
    let as_low = ours
        .iter()
        .filter(|p| p.y <= q.y)
        .min_by(|a, b| a.x.total_cmp(&b.x));
    let as_fast = ours
        .iter()
        .filter(|p| p.x <= q.x)
        .min_by(|a, b| a.y.total_cmp(&b.y));
    let low = as_low.map_or(format!("no {OURS} point is as low"), |p| {
        format!("{OURS}'s fastest as low is {}", name(p, panel))
    });
    let fast = as_fast.map_or(format!("no {OURS} point is as fast"), |p| {
        format!("its lowest as fast is {}", name(p, panel))
    });
    format!("{} — {low}; {fast}.", name(q, panel))
}

/// The summary of the scaling panel: each series' cost at a few sizes (log-log interpolation
/// between its measured sizes), and this crate's best against each peer's best there.
pub fn scaling_summary(points: &[Point]) -> Vec<String> {
    let mut series: Vec<&str> = points.iter().map(|p| p.case.series.as_str()).collect();
    series.sort_unstable();
    series.dedup();
    let mut lines = Vec::new();
    for size in [1e3, 1e4, 3e4, 1e5] {
        let at: Vec<(&str, &str, f64)> = series
            .iter()
            .filter_map(|&s| {
                let mut curve: Vec<(f64, f64, &str)> = points
                    .iter()
                    .filter(|p| p.case.series == s)
                    .map(|p| (p.x, p.y, p.case.engine.as_str()))
                    .collect();
                curve.sort_by(|a, b| a.0.total_cmp(&b.0));
                let engine = curve.first()?.2;
                Some((s, engine, interpolate(&curve, size)?))
            })
            .collect();
        if at.len() < 2 {
            continue;
        }
        let best_of = |ours: bool| {
            at.iter()
                .filter(|(_, e, _)| (*e == OURS) == ours)
                .min_by(|a, b| a.2.total_cmp(&b.2))
        };
        let listing = at
            .iter()
            .map(|(s, _, ms)| format!("{s} {} ms", sig(*ms)))
            .collect::<Vec<_>>()
            .join(", ");
        let verdict = match (best_of(true), best_of(false)) {
            (Some(o), Some(p)) if o.2 <= p.2 => format!(
                " {OURS}'s fastest ({}) is {}x faster than the fastest peer ({}).",
                o.0,
                sig(p.2 / o.2),
                p.0
            ),
            (Some(o), Some(p)) => format!(
                " {OURS}'s fastest ({}) is {}x slower than the fastest peer ({}).",
                o.0,
                sig(o.2 / p.2),
                p.0
            ),
            _ => String::new(),
        };
        lines.push(format!("At {size:.0} tets: {listing}.{verdict}"));
    }
    lines
}

/// `y` at `x` on the log-log polyline through `curve` (sorted by x), if within its range.
fn interpolate(curve: &[(f64, f64, &str)], x: f64) -> Option<f64> {
    curve.windows(2).find_map(|w| {
        let ((x0, y0, _), (x1, y1, _)) = (w[0], w[1]);
        (x0 <= x && x <= x1 && x1 > x0).then(|| {
            let t = (x.ln() - x0.ln()) / (x1.ln() - x0.ln());
            (y0.ln() + t * (y1.ln() - y0.ln())).exp()
        })
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn significant_digits() {
        assert_eq!(sig(0.012345), "0.0123");
        assert_eq!(sig(123.45), "123");
        assert_eq!(sig(1.5), "1.50");
    }

    #[test]
    fn the_front_keeps_only_undominated_points() {
        let case = |engine: &str| Case {
            engine: engine.into(),
            scene: "s".into(),
            case: "c".into(),
            series: engine.into(),
            raw: serde_json::Map::new(),
        };
        let (a, b, c, d) = (case("a"), case("b"), case("c"), case("d"));
        let at = |case, x, y| Point { case, x, y };
        let points = [
            at(&a, 1.0, 0.5),
            at(&b, 2.0, 0.1),
            at(&c, 3.0, 0.2),
            at(&d, 0.5, 0.9),
        ];
        let names: Vec<&str> = front(&points)
            .iter()
            .map(|p| p.case.engine.as_str())
            .collect();
        assert_eq!(names, ["d", "a", "b"]);
    }

    #[test]
    fn interpolation_is_exact_on_a_power_law() {
        let curve = [(1e3, 1.0, ""), (1e5, 100.0, "")];
        assert!((interpolate(&curve, 1e4).unwrap() - 10.0).abs() < 1e-9);
        assert!(interpolate(&curve, 1e6).is_none());
    }
}
