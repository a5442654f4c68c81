//! The probe position file: `{"positions": [[x, y, z], ...]}` in world units, as `kage probes
//! place` writes it and `kage probes tetrahedralize`, `kage probes lookup` and `kage render
//! --probe-positions` read it.
use crate::error::ProbeError;
use crate::files;
use glam::DVec3;
use serde::{Deserialize, Serialize};

#[derive(Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
struct PositionsFile {
    positions: Vec<[f64; 3]>,
}

/// The positions a probe file's bytes hold (a UTF-8 byte order mark allowed), or what is wrong
/// with them. The positions themselves are checked where a set is built from them.
pub fn parse(bytes: &[u8]) -> Result<Vec<DVec3>, ProbeError> {
    let file: PositionsFile = serde_json::from_slice(files::without_bom(bytes))
        .map_err(|e| ProbeError::File { problem: e.to_string() })?;
    Ok(file.positions.into_iter().map(DVec3::from_array).collect())
}

/// The file's text for `positions`, one line.
pub fn to_json(positions: &[DVec3]) -> String {
    let file = PositionsFile { positions: positions.iter().map(|p| p.to_array()).collect() };
    serde_json::to_string(&file).expect("arrays of f64 serialize") + "\n"
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn positions_round_trip_and_bad_files_are_named() {
        let positions = vec![DVec3::new(1.0, -2.5, 3.0), DVec3::ZERO];
        assert_eq!(parse(to_json(&positions).as_bytes()).unwrap(), positions);
        assert_eq!(parse(b"\xEF\xBB\xBF{\"positions\": []}").unwrap(), Vec::<DVec3>::new());
        for bad in [&b"{\"positions\": [[1, 2]]}"[..], b"{\"points\": []}", b"\xff", b""] {
            let error = parse(bad).unwrap_err().to_string();
            assert!(error.contains("not a probe file"), "{error}");
        }
    }
}
