//! The answers a sweep gives: the Pareto front of time against error, and the setting to pick
//! under an error or a time bound.

/// One measured setting: its GPU time per frame and its error.
#[derive(Clone, Debug, PartialEq)]
pub struct Point {
    /// The chart's series: the technique and what its labels count (`tamura (q)`).
    pub series: String,
    /// The setting's name (`tamura:32`).
    pub name: String,
    /// Its label on the chart (`32`).
    pub label: String,
    pub ms: f64,
    pub error: f64,
}

/// Indices of the points no other point beats in both time and error, cheapest first.
pub fn pareto_front(points: &[Point]) -> Vec<usize> {
    let mut order: Vec<usize> = (0..points.len()).collect();
    order.sort_by(|&a, &b| {
        points[a].ms.total_cmp(&points[b].ms).then(points[a].error.total_cmp(&points[b].error))
    });
    let mut best = f64::INFINITY;
    order
        .into_iter()
        .filter(|&i| {
            let better = points[i].error < best;
            best = best.min(points[i].error);
            better
        })
        .collect()
}

/// The cheapest point whose error is at most `max_error`.
pub fn cheapest_within(points: &[Point], max_error: f64) -> Option<&Point> {
    points.iter().filter(|p| p.error <= max_error).min_by(|a, b| a.ms.total_cmp(&b.ms))
}

/// The most accurate point whose time is at most `max_ms`.
pub fn most_accurate_within(points: &[Point], max_ms: f64) -> Option<&Point> {
    points.iter().filter(|p| p.ms <= max_ms).min_by(|a, b| a.error.total_cmp(&b.error))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn points() -> Vec<Point> {
        [("a", 1.0, 0.5), ("b", 2.0, 0.2), ("c", 3.0, 0.3), ("d", 4.0, 0.1), ("e", 2.0, 0.4)]
            .into_iter()
            .map(|(name, ms, error)| Point {
                series: "t".into(),
                name: name.into(),
                label: String::new(),
                ms,
                error,
            })
            .collect()
    }

    #[test]
    fn the_front_keeps_what_nothing_beats() {
        // c is beaten by b (faster and better), e by b (as fast, better).
        assert_eq!(pareto_front(&points()), vec![0, 1, 3]);
    }

    #[test]
    fn picks_answer_both_bounds() {
        let p = points();
        assert_eq!(cheapest_within(&p, 0.3).unwrap().name, "b");
        assert_eq!(cheapest_within(&p, 0.1).unwrap().name, "d");
        assert!(cheapest_within(&p, 0.05).is_none());
        assert_eq!(most_accurate_within(&p, 3.5).unwrap().name, "b");
        assert_eq!(most_accurate_within(&p, 1.0).unwrap().name, "a");
        assert!(most_accurate_within(&p, 0.5).is_none());
    }
}
