//! What can be wrong with a probe set or a lookup point.

#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum ProbeError {
    #[error("probe {index} at {position:?}: {problem}")]
    BadPosition { index: usize, position: [f64; 3], problem: &'static str },
    #[error("lookup point {position:?}: {problem}")]
    BadPoint { position: [f64; 3], problem: &'static str },
    #[error(
        "{distinct} distinct probe position(s) among the {total} given: a tetrahedralization needs at least 4"
    )]
    TooFew { distinct: usize, total: usize },
    #[error("all {distinct} distinct probe positions lie {shape}: a tetrahedralization needs 4 that do not lie in one plane")]
    Flat { distinct: usize, shape: &'static str },
    #[error("{total} probes given: at most {max} are supported")]
    TooMany { total: usize, max: usize },
}

/// Coordinates beyond this are refused: the exact in-sphere test multiplies five coordinate
/// differences, and its expansions must not overflow.
pub const MAX_COORDINATE: f64 = 1e30;

/// Why a position cannot be used, if it cannot.
pub fn position_problem(p: [f64; 3]) -> Option<&'static str> {
    if !p.iter().all(|c| c.is_finite()) {
        Some("coordinates must be finite")
    } else if p.iter().any(|c| c.abs() > MAX_COORDINATE) {
        Some("coordinates must be within ±1e30")
    } else {
        None
    }
}
