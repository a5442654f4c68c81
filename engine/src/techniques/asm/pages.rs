//! The GPU side of the page pool ([`super::pool`]): the atlas every page lives in, and the
//! recording of the pool's page operations. Pages are slots of tiles and need not lie side
//! by side in the atlas, so every page write goes through a scratch target of
//! [`SCRATCH_TILES`] tiles side by side: tiles render into it whole, in one rendering scope,
//! and their stored slots are copied out together (a CPU rasterizer waits at every barrier
//! and pays for every scope, so a copy and a scope per tile cost more than the tile's
//! triangles). The scratch counts in the budget.
//!
//! The polygon-ID test keeps a second atlas and scratch, of IDs, laid out as the depth ones.
use super::pool::{SLOT_SIDE, TILE_PAGES};
use super::tile::TileKey;
use crate::backend::{
    Binding, Cmd, Context, Depth, DepthTest, Edge, Format, GraphicsDesc, GraphicsPipeline, Image, ImageDesc,
    ImageUsage, Sampler, Target, Topology,
};
use crate::error::{Error, Result};
use crate::frame::gpu_scene::MESH_POSITIONS;
use crate::frame::shadow_depth::ShadowMaps;
use crate::frame::{GpuScene, DEPTH_FORMAT};
use crate::layouts::constants::{ASM_PAGE_TEXELS, ASM_TILE_TEXELS};
use crate::layouts::{bytes_of, spirv, AsmTilePush};
use glam::Mat4;
use std::sync::Arc;

/// The ID test's polygon IDs.
const ID_FORMAT: Format = Format::R32_UINT;
/// Most pages per atlas row: 16384 texels, the largest image side of lavapipe and NVIDIA.
const MAX_COLUMNS: u32 = 16384 / ASM_PAGE_TEXELS;
/// Tiles the scratch holds: renders between two copies into the atlas.
pub const SCRATCH_TILES: u32 = 4;
/// Texels a side of the scratch: its tiles 2 × 2.
const SCRATCH_SIDE: u32 = 2 * ASM_TILE_TEXELS;

/// Bytes of the scratch for pages of `page_bytes`.
pub fn scratch_bytes(page_bytes: u64) -> u64 {
    u64::from(SCRATCH_TILES) * TILE_PAGES * page_bytes
}

/// How the atlas lays its pages out: row by row, `columns` to a row.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct AtlasLayout {
    pub columns: u32,
    pub rows: u32,
}

impl AtlasLayout {
    /// The atlas of the most pages of `page_bytes` that fit in `bytes` (rows and columns as
    /// near equal as that count allows, so that its sides stay small); an error below one
    /// tile's pages.
    pub fn within(bytes: u64, page_bytes: u64) -> Result<AtlasLayout> {
        let pages = u32::try_from(bytes / page_bytes).unwrap_or(u32::MAX);
        if u64::from(pages) < TILE_PAGES {
            return Err(Error::InvalidArgument(format!(
                "{bytes} bytes hold no ASM tile: a tile takes {} bytes",
                TILE_PAGES * page_bytes
            )));
        }
        let square = (f64::from(pages).sqrt().ceil() as u32).min(MAX_COLUMNS);
        let best = (square..=MAX_COLUMNS.min(pages).max(square))
            .map(|columns| AtlasLayout { columns, rows: pages / columns })
            .max_by_key(|l| (l.pages(), std::cmp::Reverse(l.columns)))
            .expect("the range holds `square`");
        Ok(best)
    }

    pub fn pages(&self) -> u32 {
        self.columns * self.rows
    }

    /// The page's cell in the atlas as `AsmNode.pages` holds it: column | row << 12 (at most
    /// `MAX_COLUMNS` of each, the largest image side over a page's).
    pub fn cell(&self, page: u32) -> u32 {
        (page % self.columns) | ((page / self.columns) << 12)
    }

    /// The page's first texel in the atlas.
    fn origin(&self, page: u32) -> [u32; 2] {
        [page % self.columns * ASM_PAGE_TEXELS, page / self.columns * ASM_PAGE_TEXELS]
    }
}

/// A tile render of this frame (`super::pool::PageOp`): the square of `key`, its slots
/// `stores` names stored in their pages.
pub struct TileWrite {
    pub key: TileKey,
    /// (slot, page) pairs.
    pub stores: Vec<(u32, u32)>,
    /// The light's projection cropped to the tile's square.
    pub view_proj: Mat4,
    /// The index runs it draws: (mesh of the scene, first index, index count).
    pub draws: Vec<(usize, u32, u32)>,
}

struct IdPages {
    atlas: Image,
    scratch: Image,
    /// Renders a tile's depth and IDs.
    tile: GraphicsPipeline,
    /// Each mesh's first ID (by group, then mesh).
    first: Vec<Vec<u32>>,
}

pub struct PageStore {
    layout: AtlasLayout,
    atlas: Image,
    /// One tile of depth, rendered with the shadow-depth pipeline.
    scratch: ShadowMaps,
    ids: Option<IdPages>,
    nearest: Sampler,
}

impl PageStore {
    /// The atlas of at most `most_pages` pages of `page_bytes` (the budget's share,
    /// [`super::memory::AsmMemory::within`]) and the scratch; with polygon IDs when `ids`
    /// (`page_bytes` then counts a depth and an ID per texel).
    pub fn new(
        ctx: &Arc<Context>,
        gpu: &GpuScene,
        most_pages: u32,
        page_bytes: u64,
        ids: bool,
    ) -> Result<PageStore> {
        let layout = AtlasLayout::within(u64::from(most_pages) * page_bytes, page_bytes)?;
        let (width, height) = (layout.columns * ASM_PAGE_TEXELS, layout.rows * ASM_PAGE_TEXELS);
        let atlas_usage = ImageUsage::SAMPLED | ImageUsage::TRANSFER_DST;
        let atlas = |name, format| {
            let desc = ImageDesc {
                name,
                width,
                height,
                layers: 1,
                levels: 1,
                array: false,
                format,
                usage: atlas_usage,
            };
            Image::new(ctx, &desc).map_err(|e| match e {
                Error::InvalidArgument(e) => {
                    Error::InvalidArgument(format!("an ASM budget of {} pages: {e}", layout.pages()))
                }
                e => e,
            })
        };
        let depth_atlas = atlas("asm.atlas", DEPTH_FORMAT)?;
        let ids = if ids { Some(IdPages::new(ctx, gpu, atlas("asm.id_atlas", ID_FORMAT)?)?) } else { None };
        Ok(PageStore {
            layout,
            atlas: depth_atlas,
            scratch: ShadowMaps::new(ctx, "asm.scratch", SCRATCH_SIDE, 1)?,
            ids,
            nearest: Sampler::new(ctx, "asm.pages_sampler", false, Edge::Clamp, Edge::Clamp)?,
        })
    }

    pub fn layout(&self) -> AtlasLayout {
        self.layout
    }

    /// The depth atlas as the lookups sample it.
    pub fn depth_binding(&self) -> Binding<'_> {
        Binding::Sampled(&self.atlas, &self.nearest)
    }

    /// The ID atlas as the lookups sample it, for the ID test.
    pub fn id_binding(&self) -> Option<Binding<'_>> {
        self.ids.as_ref().map(|ids| Binding::Sampled(&ids.atlas, &self.nearest))
    }

    /// The polygon ID of the first triangle of mesh `mesh` of group `group` (0 without IDs).
    pub fn first_id(&self, group: usize, mesh: usize) -> u32 {
        self.ids.as_ref().map_or(0, |ids| ids.first[group][mesh])
    }

    /// Records `writes` in order, one debug label each.
    pub fn record(&self, ctx: &Context, cmd: Cmd, scene: &GpuScene, writes: &[TileWrite]) {
        for batch in writes.chunks(SCRATCH_TILES as usize) {
            self.begin_batch(ctx, cmd);
            // Squares of the scratch to store (their first texel), with their pages.
            let mut squares: Vec<([u32; 2], u32)> = Vec::new();
            for (i, write) in batch.iter().enumerate() {
                let key = write.key;
                ctx.begin_label(cmd, &format!("asm_tile L{} ({}, {})", key.level, key.x, key.y));
                let at = [i as u32 % 2 * ASM_TILE_TEXELS, i as u32 / 2 * ASM_TILE_TEXELS];
                ctx.restrict_to_square(cmd, at, ASM_TILE_TEXELS);
                self.draw_tile(ctx, cmd, scene, write);
                for &(slot, page) in &write.stores {
                    let from = [
                        at[0] + slot % SLOT_SIDE * ASM_PAGE_TEXELS,
                        at[1] + slot / SLOT_SIDE * ASM_PAGE_TEXELS,
                    ];
                    squares.push((from, page));
                }
                ctx.end_label(cmd);
            }
            ctx.end_rendering(cmd);
            self.store(cmd, squares);
        }
    }

    /// Opens the rendering scope of a batch: the scratch cleared, depth and IDs for the ID test.
    fn begin_batch(&self, ctx: &Context, cmd: Cmd) {
        let Some(ids) = &self.ids else { return self.scratch.begin(ctx, cmd, 0) };
        let color = Target { image: &ids.scratch, layer: 0 };
        ctx.begin_rendering(cmd, Some(color), Some([0.0; 4]), Some(Depth::Clear(self.scratch.target(0))));
        ids.tile.bind(cmd, &[]);
    }

    /// A tile's draws into the part of the scratch the scope is restricted to.
    fn draw_tile(&self, ctx: &Context, cmd: Cmd, scene: &GpuScene, write: &TileWrite) {
        let draws = write.draws.iter().map(|&(m, first, count)| (&scene.meshes[m], first, count));
        let Some(ids) = &self.ids else {
            return self.scratch.draw(ctx, cmd, scene, &write.view_proj, draws);
        };
        for (mesh, first, count) in draws {
            // gl_PrimitiveID counts from the run's first triangle.
            let push = AsmTilePush {
                transform: (write.view_proj * scene.transforms[mesh.group]).to_cols_array_2d(),
                ids: [ids.first[mesh.group][mesh.mesh] + first / 3, 0, 0, 0],
            };
            ids.tile.push(cmd, bytes_of(&push));
            ctx.draw_indexed_range(cmd, &[&mesh.vertices], &mesh.indices, first, count);
        }
    }

    /// Copies squares of the scratch (each with the page it goes to) into the atlases. A page
    /// written twice keeps the later square: a slot given back by a tile and taken by another
    /// rendered after it in the same batch.
    fn store(&self, cmd: Cmd, pending: Vec<([u32; 2], u32)>) {
        let mut seen = std::collections::HashSet::new();
        let mut squares: Vec<([u32; 2], [u32; 2])> = pending
            .into_iter()
            .rev()
            .filter(|(_, page)| seen.insert(*page))
            .map(|(from, page)| (from, self.layout.origin(page)))
            .collect();
        if squares.is_empty() {
            return;
        }
        squares.reverse();
        self.scratch.image().record_copy_squares(cmd, &self.atlas, &squares, ASM_PAGE_TEXELS);
        if let Some(ids) = &self.ids {
            ids.scratch.record_copy_squares(cmd, &ids.atlas, &squares, ASM_PAGE_TEXELS);
        }
    }
}

impl IdPages {
    fn new(ctx: &Arc<Context>, gpu: &GpuScene, atlas: Image) -> Result<IdPages> {
        let usage = ImageUsage::COLOR_ATTACHMENT | ImageUsage::TRANSFER_SRC;
        let desc = ImageDesc::square_array("asm.id_scratch", SCRATCH_SIDE, 1, ID_FORMAT, usage);
        let tile = GraphicsPipeline::new(
            ctx,
            &GraphicsDesc {
                name: "asm.tile_ids",
                vertex_spirv: spirv::ASM_TILE_VERT,
                fragment_spirv: spirv::ASM_TILE_FRAG,
                bindings: &[],
                push_size: size_of::<AsmTilePush>() as u32,
                vertex_buffers: &[MESH_POSITIONS],
                topology: Topology::Triangles,
                color_formats: &[ID_FORMAT],
                depth_format: Some(DEPTH_FORMAT),
                depth: DepthTest::Less,
                write_color: true,
                constants: &[],
            },
        )?;
        // IDs from 1 (0 is a texel no surface covers), numbered mesh after mesh.
        let mut next = 1u32;
        let mut first: Vec<Vec<u32>> = Vec::new();
        for mesh in &gpu.meshes {
            if first.len() <= mesh.group {
                first.resize(mesh.group + 1, Vec::new());
            }
            let of_group = &mut first[mesh.group];
            if of_group.len() <= mesh.mesh {
                of_group.resize(mesh.mesh + 1, 0);
            }
            of_group[mesh.mesh] = next;
            next += mesh.index_count / 3;
        }
        Ok(IdPages { atlas, scratch: Image::new(ctx, &desc)?, tile, first })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_atlas_holds_what_the_bytes_allow_near_square() {
        let page = 4096;
        for (pages, expected) in [(16, (4, 4)), (1020, (34, 30)), (4092, (66, 62)), (1021, (1021, 1))] {
            let layout = AtlasLayout::within(pages * page + page / 2, page).unwrap();
            assert_eq!((layout.columns, layout.rows), expected, "{pages} pages");
            assert!(u64::from(layout.pages()) <= pages && layout.rows <= layout.columns);
        }
        assert!(AtlasLayout::within((TILE_PAGES - 1) * page, page).is_err());
        let layout = AtlasLayout { columns: 34, rows: 30 };
        assert_eq!(layout.cell(35), 1 | 1 << 12);
        assert_eq!(layout.origin(35), [ASM_PAGE_TEXELS, ASM_PAGE_TEXELS]);
    }
}
