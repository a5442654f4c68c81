//! Probe positions as the tetrahedralization takes them: validated, duplicates merged.
use crate::error::ProbeError;
use glam::DVec3;

/// The most probes a set may have, so that tetrahedra (about 6.5 per point) fit u32 numbers.
pub const MAX_PROBES: usize = 1 << 26;

/// Coordinates beyond this are refused: the exact in-sphere test multiplies five coordinate
/// differences, and its expansions must not overflow.
const LARGEST: f64 = 1e30;
/// Coordinates nearer 0 than this are taken as 0, so that every difference of coordinates is 0
/// or above 1e-46 and the predicates' products (up to the fifth power) cannot underflow.
const SMALLEST: f64 = 1e-30;

/// The position as the predicates can use it (coordinates below 1e-30 in magnitude set to 0),
/// or why it cannot be used.
pub fn usable(p: DVec3) -> Result<DVec3, &'static str> {
    if !p.is_finite() {
        Err("coordinates must be finite")
    } else if p.abs().max_element() > LARGEST {
        Err("coordinates must be within ±1e30")
    } else {
        // Adding 0.0 also turns -0.0 into +0.0, so that equal positions compare equal bitwise.
        Ok(DVec3::select(p.abs().cmplt(DVec3::splat(SMALLEST)), DVec3::ZERO, p) + 0.0)
    }
}

/// A duplicate probe position: `index` was dropped in favour of the identical `kept`.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Merged {
    pub index: u32,
    pub kept: u32,
}

/// The usable positions (see [`usable`]), the distinct ones in input order with the input index
/// of each, and the merges made.
pub struct Distinct {
    pub all: Vec<DVec3>,
    pub points: Vec<DVec3>,
    pub input_index: Vec<u32>,
    pub merged: Vec<Merged>,
}

/// Refuses more than [`MAX_PROBES`] probes, before their positions are allocated.
pub fn check_count(total: usize) -> Result<(), ProbeError> {
    match total > MAX_PROBES {
        true => Err(ProbeError::TooMany { total, max: MAX_PROBES }),
        false => Ok(()),
    }
}

pub fn distinct(positions: &[DVec3]) -> Result<Distinct, ProbeError> {
    check_count(positions.len())?;
    let positions = positions
        .iter()
        .enumerate()
        .map(|(index, &p)| {
            usable(p).map_err(|problem| ProbeError::BadPosition { index, position: p.to_array(), problem })
        })
        .collect::<Result<Vec<DVec3>, _>>()?;
    let key = |i: u32| positions[i as usize].to_array();
    let lexicographic = |a: &u32, b: &u32| {
        let (ka, kb) = (key(*a), key(*b));
        (0..3).map(|k| ka[k].total_cmp(&kb[k])).find(|o| o.is_ne()).unwrap_or(a.cmp(b))
    };
    let mut sorted: Vec<u32> = (0..positions.len() as u32).collect();
    sorted.sort_unstable_by(lexicographic);
    let mut input_index = Vec::with_capacity(positions.len());
    let mut merged = Vec::new();
    for (k, &i) in sorted.iter().enumerate() {
        match k.checked_sub(1).map(|prev| sorted[prev]) {
            // Sorted by index within equal positions: the first of a run is kept.
            Some(prev) if key(prev) == key(i) => {
                let kept = merged.last().filter(|m: &&Merged| m.index == prev).map_or(prev, |m| m.kept);
                merged.push(Merged { index: i, kept });
            }
            _ => input_index.push(i),
        }
    }
    input_index.sort_unstable();
    merged.sort_unstable_by_key(|m| m.index);
    let points = input_index.iter().map(|&i| positions[i as usize]).collect();
    Ok(Distinct { all: positions, points, input_index, merged })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn duplicates_merge_into_the_first_occurrence() {
        let p = |x: f64| DVec3::new(x, 0.0, 0.0);
        let d = distinct(&[p(1.0), p(2.0), p(1.0), p(-0.0), p(0.0), p(1.0)]).unwrap();
        assert_eq!(d.input_index, [0, 1, 3]);
        assert_eq!(
            d.merged,
            [Merged { index: 2, kept: 0 }, Merged { index: 4, kept: 3 }, Merged { index: 5, kept: 0 }]
        );
        assert_eq!(d.points, [p(1.0), p(2.0), p(-0.0)]);
    }

    #[test]
    fn bad_positions_are_named() {
        let e = distinct(&[DVec3::ZERO, DVec3::new(0.0, f64::NAN, 0.0)]).err().unwrap();
        assert!(matches!(e, ProbeError::BadPosition { index: 1, .. }), "{e}");
        let e = distinct(&[DVec3::new(2e30, 0.0, 0.0)]).err().unwrap();
        assert!(e.to_string().contains("probe 0") && e.to_string().contains("1e30"), "{e}");
    }

    #[test]
    fn coordinates_nearer_zero_than_1e_30_are_zero() {
        let d = distinct(&[DVec3::new(1e-31, -1e-300, 2e-30), DVec3::new(0.0, 0.0, 2e-30)]).unwrap();
        assert_eq!(d.all[0], DVec3::new(0.0, 0.0, 2e-30));
        assert_eq!(d.merged, [Merged { index: 1, kept: 0 }]);
    }
}
