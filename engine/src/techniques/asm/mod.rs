//! Adaptive Shadow Maps (Fernando, Fernandez, Bala, Greenberg 2001; ../shared/papers/README.md
//! section 2).
//!
//! - [`technique`]: the technique: the eye view's analysis, then in the same frame tile
//!   rendering and lookup; invalidation.
//! - [`plan`]: which requested tiles a frame renders (benefit / cost within a time budget,
//!   every tile after its parent).
//! - [`light_view`]: tile projections and the light-uv bounds of groups.
//! - [`tile`]: the quadtree of tiles over the light's view; a tile at level L covers 1/2^L of
//!   the view's side and holds `ASM_TILE_TEXELS`² texels, so each level doubles the resolution.
//! - [`pool`]: the physical page pool: one page per resident tile, as many pages as a byte
//!   budget holds (never more), least-recently-used eviction of leaf tiles.
//! - [`page_table`]: the resident tree flattened into `AsmNode` records for the GPU lookup
//!   (shaders-glsl/include/layouts.glsl) behind a directory of one level's tiles: start at the
//!   directory's tile and descend while the child holding the point is resident; the last node reached is the finest resident tile, so a missing tile
//!   falls back to its nearest resident ancestor, at worst the root (always resident), never to
//!   "lit".
pub mod light_view;
pub mod page_table;
pub mod plan;
pub mod pool;
pub mod technique;
pub mod tile;

pub use technique::{AsmSettings, AsmStats};
