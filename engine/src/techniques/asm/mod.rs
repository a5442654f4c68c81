//! Adaptive Shadow Maps (Fernando, Fernandez, Bala, Greenberg 2001).
//!
//! - [`technique`]: the technique: the eye view's analysis, then in the same frame tile
//!   rendering and lookup; invalidation.
//! - [`plan`]: which requested tiles a frame renders (benefit / cost within a time budget,
//!   every tile after its parent).
//! - [`light_view`]: tile projections and the light-uv bounds of groups.
//! - [`tile`]: the quadtree of tiles over the light's view; a tile at level L covers 1/2^L of
//!   the view's side and is rendered at `ASM_TILE_TEXELS`² texels, so each level doubles the
//!   resolution.
//! - [`pool`]: the physical page pool: a page is one slot of a tile (a 4 × 4 grid), and a
//!   resident tile keeps pages only for the slots the analysis asked for that its resident
//!   children do not cover (a new tile all of them for a few frames, its trial); as many pages
//!   as a byte budget holds (never more), least-recently-used eviction of leaf tiles.
//! - [`pages`]: the pool on the GPU: pages of 16-bit depths over each slot's own span, and the
//!   tile renders (through a scratch target, each drawing only the triangle clusters over its
//!   square, then packed) that fill them.
//! - [`page_table`]: the resident tree flattened into `AsmNode` records for the GPU lookup
//!   (shaders-glsl/include/layouts.glsl) behind a directory of one level's tiles: start at the
//!   directory's tile and descend, two levels a step, while the tile holding the point is
//!   resident; the last node reached is the finest resident tile, whose entry for the slot
//!   holding the point names that slot's page or the nearest ancestor's that holds it, at worst
//!   the root's (always resident, every slot wanted), never "lit".
pub mod light_view;
pub mod memory;
pub mod page_table;
pub mod pages;
pub mod plan;
pub mod pool;
pub mod technique;
pub mod tile;

pub use technique::{AsmSettings, AsmStats, AsmTimeBudget};
