//! Light probe positions a scene file places by hand (Morishige 2014 places them by hand too,
//! each for a reason): `kage render --technique probes --probes scene` captures at them.

use glam::Vec3;
use serde::{Deserialize, Serialize};

/// Why a probe stands where it does. Kage captures and interpolates every probe alike; the
/// role documents the placement (for the author and for tools that place or prune probes).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum ProbeRole {
    /// Where the open sky's light changes: under openings, at the edge of a shadow.
    Sky,
    /// Near a lit surface, to catch the light it reflects.
    Bounce,
    /// Near a strongly coloured surface, to catch its colour bleeding.
    Bleed,
}

#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SceneProbe {
    pub position: Vec3,
    pub role: Option<ProbeRole>,
}
