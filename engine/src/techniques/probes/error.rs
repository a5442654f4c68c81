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
    #[error("the least-squares fit of {probes} probes' SH did not converge")]
    FitDiverged { probes: usize },
    #[error("{total} probes given: at most {max} are supported")]
    TooMany { total: usize, max: usize },
}
