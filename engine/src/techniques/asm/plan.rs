//! The refinement planner (Fernando et al. 2001, section 4.2): which requested tiles to render
//! this frame. A request is a tile and the slots of it (`pool`) that the analysis found eye
//! pixels on a shadow edge in, whose shadow resolution is coarser than the eye's.
//!
//! - Benefit: edge pixels × resolution deficit, the deficit being the mean number of levels
//!   (factors of two in texel size) those pixels lack.
//! - Cost: a·N + b milliseconds, N the triangles drawn for the tile (the groups whose light-uv
//!   bounds overlap it), a and b fitted by least squares to timed tile renders on the running
//!   device ([`CostModel::fit`]) at start-up, and scaled frame by frame by how long the tiles
//!   the model planned took (`Asm::timed`): tiles timed one by one at start-up and tiles
//!   rendered back to back in a frame cost differently on some devices (4x on lavapipe).
//! - Requests are taken by benefit/cost, best first, until what the taken ones planned (their
//!   renders and those of the ancestors their evictions give slots back to, each tile once a
//!   frame) and the next one's cost would pass the per-frame time budget. A request's
//!   evictions are made only within the budget left after its own render; the best one's own
//!   render is always made, so that the refinement progresses on a device slower than the
//!   budget assumes. The pool makes the tiles between a request and its nearest resident
//!   ancestor resident without pages.
use super::pool::Slots;
use super::tile::TileKey;

/// Slots of a tile the analysis asked for.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Request {
    pub key: TileKey,
    pub slots: Slots,
    /// Eye pixels on a shadow edge inside them, short of resolution.
    pub edge_pixels: u32,
    /// Their missing levels, summed.
    pub missing_levels: u32,
    /// Triangles a render of the tile draws.
    pub triangles: u64,
}

impl Request {
    pub fn benefit(&self) -> f64 {
        // edge pixels × mean deficit = the sum of the pixels' deficits.
        f64::from(self.missing_levels)
    }
}

/// Milliseconds to render a tile of N triangles: a·N + b.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct CostModel {
    pub ms_per_triangle: f64,
    pub ms_per_tile: f64,
}

impl CostModel {
    pub fn cost_ms(&self, triangles: u64) -> f64 {
        self.ms_per_triangle * triangles as f64 + self.ms_per_tile
    }

    /// The model with both coefficients times `factor`.
    pub fn scaled(&self, factor: f64) -> CostModel {
        CostModel { ms_per_triangle: self.ms_per_triangle * factor, ms_per_tile: self.ms_per_tile * factor }
    }

    /// The least-squares line through (triangles, ms) samples. Both coefficients are kept
    /// positive (a timing can only grow with work; a tile is never free): with samples that
    /// all draw the same N, or noise that tilts the line below zero, the model falls back to a
    /// per-tile mean with a at 0, or to the line through the origin.
    pub fn fit(samples: &[(u64, f64)]) -> CostModel {
        const FLOOR_MS: f64 = 1e-3;
        let n = samples.len() as f64;
        if samples.is_empty() {
            return CostModel { ms_per_triangle: 0.0, ms_per_tile: FLOOR_MS };
        }
        let mean_x = samples.iter().map(|s| s.0 as f64).sum::<f64>() / n;
        let mean_y = samples.iter().map(|s| s.1).sum::<f64>() / n;
        let sxx: f64 = samples.iter().map(|s| (s.0 as f64 - mean_x).powi(2)).sum();
        let sxy: f64 = samples.iter().map(|s| (s.0 as f64 - mean_x) * (s.1 - mean_y)).sum();
        let flat = CostModel { ms_per_triangle: 0.0, ms_per_tile: mean_y.max(FLOOR_MS) };
        if sxx <= 0.0 || sxy <= 0.0 {
            return flat;
        }
        let a = sxy / sxx;
        let b = mean_y - a * mean_x;
        if b >= FLOOR_MS {
            return CostModel { ms_per_triangle: a, ms_per_tile: b };
        }
        let sx2: f64 = samples.iter().map(|s| (s.0 as f64).powi(2)).sum();
        let sxy0: f64 = samples.iter().map(|s| s.0 as f64 * s.1).sum();
        CostModel { ms_per_triangle: (sxy0 / sx2).max(0.0), ms_per_tile: FLOOR_MS }
    }
}

/// The factor on the start-up model after a frame whose tiles the model (times 1) predicted
/// at `predicted_ms` took `measured_ms`: the geometric mean of the old factor and this frame's
/// ratio (clamped to 1/20–20), so that it follows the device within a few frames and one noisy
/// timing moves it by at most the square root of its error.
pub fn rescaled(scale: f64, predicted_ms: f64, measured_ms: f64) -> f64 {
    (scale * (measured_ms / predicted_ms).clamp(0.05, 20.0)).sqrt()
}

/// Takes the requests to render this frame within `budget_ms`, the best benefit/cost first.
/// `take(request, left)` takes one with `left` ms of the budget left, and returns the ms it
/// planned by the model (its render and the renders its evictions need) and whether the tile
/// was taken (one refused may have planned renders: evictions done before the pool gave up).
/// The best is always tried; returns the requests taken, in order.
pub fn plan(
    mut requests: Vec<Request>,
    model: &CostModel,
    budget_ms: f64,
    mut take: impl FnMut(&Request, f64) -> (f64, bool),
) -> Vec<Request> {
    let ratio = |r: &Request| r.benefit() / model.cost_ms(r.triangles);
    requests.retain(|r| r.benefit() > 0.0);
    requests.sort_by(|a, b| ratio(b).total_cmp(&ratio(a)).then(a.key.cmp(&b.key)));
    let mut spent = 0.0;
    let mut taken = Vec::new();
    for (i, r) in requests.into_iter().enumerate() {
        if i > 0 && spent + model.cost_ms(r.triangles) > budget_ms {
            break;
        }
        let (ms, took) = take(&r, budget_ms - spent);
        spent += ms;
        if took {
            taken.push(r);
        }
    }
    taken
}

#[cfg(test)]
mod tests {
    use super::*;

    fn request(x: u32, edge_pixels: u32, missing_levels: u32, triangles: u64) -> Request {
        Request { key: TileKey { level: 1, x, y: 0 }, slots: 1, edge_pixels, missing_levels, triangles }
    }

    #[test]
    fn the_fit_recovers_a_line_and_stays_positive() {
        let line: Vec<(u64, f64)> = [100, 1000, 5000].iter().map(|&n| (n, 0.002 * n as f64 + 0.5)).collect();
        let m = CostModel::fit(&line);
        assert!((m.ms_per_triangle - 0.002).abs() < 1e-9 && (m.ms_per_tile - 0.5).abs() < 1e-9, "{m:?}");
        // Same N everywhere: the mean.
        let m = CostModel::fit(&[(10, 1.0), (10, 3.0)]);
        assert_eq!(m, CostModel { ms_per_triangle: 0.0, ms_per_tile: 2.0 });
        // Falling with N (noise): no negative slope.
        assert_eq!(CostModel::fit(&[(10, 3.0), (20, 1.0)]).ms_per_triangle, 0.0);
        // Steep through the origin: the intercept would be negative; kept at the floor.
        let m = CostModel::fit(&[(10, 0.5), (20, 2.0)]);
        assert!(m.ms_per_triangle > 0.0 && m.ms_per_tile > 0.0, "{m:?}");
        assert!(CostModel::fit(&[]).ms_per_tile > 0.0);
    }

    #[test]
    fn requests_are_taken_by_benefit_over_cost_within_the_budget() {
        let model = CostModel { ms_per_triangle: 0.001, ms_per_tile: 1.0 };
        // Costs: 2 ms, 2 ms, 11 ms, 2 ms; benefits 10, 40, 1000, 0.
        let requests = vec![
            request(0, 5, 10, 1000),
            request(1, 20, 40, 1000),
            request(2, 400, 1000, 10_000),
            request(3, 0, 0, 1000),
        ];
        let keys = |chosen: Vec<Request>| chosen.iter().map(|r| r.key.x).collect::<Vec<_>>();
        // Each take planned its tile's cost.
        let render = |r: &Request, _| (model.cost_ms(r.triangles), true);
        // Ratios: 5, 20, 90.9: the big one first; then the 2 ms ones only if they fit.
        assert_eq!(keys(plan(requests.clone(), &model, 15.0, render)), vec![2, 1, 0]);
        assert_eq!(keys(plan(requests.clone(), &model, 13.0, render)), vec![2, 1]);
        // The best is taken even when it alone is over budget; nothing after it then.
        assert_eq!(keys(plan(requests.clone(), &model, 1.0, render)), vec![2]);
        // No benefit, no request.
        assert!(plan(vec![request(3, 0, 0, 1)], &model, 100.0, render).is_empty());
        // What a take planned beyond its tile (an eviction's render) counts: with the big one's
        // 11 ms, a 2 ms one fits in 14; with an eviction's 2 ms more, none does.
        assert_eq!(keys(plan(requests.clone(), &model, 14.0, render)), vec![2, 1]);
        let evicting = |r: &Request, _| (model.cost_ms(r.triangles) + 2.0, true);
        assert_eq!(keys(plan(requests.clone(), &model, 14.0, evicting)), vec![2]);
        // A refused take is skipped, the next taken.
        let refusing =
            |r: &Request, _| if r.key.x == 2 { (0.0, false) } else { (model.cost_ms(r.triangles), true) };
        assert_eq!(keys(plan(requests.clone(), &model, 15.0, refusing)), vec![1, 0]);
        // The best refused after its evictions planned 12 ms: the next (2 ms) fits in 15, no
        // more; in 13 none does.
        let evicted =
            |r: &Request, _| if r.key.x == 2 { (12.0, false) } else { (model.cost_ms(r.triangles), true) };
        assert_eq!(keys(plan(requests.clone(), &model, 15.0, evicted)), vec![1]);
        assert!(keys(plan(requests.clone(), &model, 13.0, evicted)).is_empty());
        // Each take is told the budget left before it.
        let mut lefts = Vec::new();
        plan(requests, &model, 15.0, |r, left| {
            lefts.push(left);
            render(r, left)
        });
        assert_eq!(lefts, vec![15.0, 4.0, 2.0]);
    }

    #[test]
    fn the_scale_follows_the_measured_cost_and_damps_outliers() {
        // Tiles that take 4x the model's prediction, frame after frame: within 1 % in 8 frames.
        let mut scale = 1.0;
        for _ in 0..8 {
            scale = rescaled(scale, 2.0, 8.0);
        }
        assert!((scale - 4.0).abs() < 0.04, "{scale}");
        // One frame 16x off moves a settled factor by 4x at most, never to 16x.
        assert!((rescaled(1.0, 1.0, 16.0) - 4.0).abs() < 1e-12);
        // Absurd timings are clamped.
        assert!((rescaled(1.0, 1.0, 1e9) - 20f64.sqrt()).abs() < 1e-12);
    }
}
