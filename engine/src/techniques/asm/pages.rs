//! The GPU side of the page pool ([`super::pool`]): the pages in texel buffers, and the
//! recording of the pool's page operations. Pages are slots of tiles and need not lie side by
//! side, so every page write goes through a scratch target of tiles side by side: tiles render
//! into it whole, then `asm_pack.comp` packs their stored slots into 16-bit pages (half of
//! D32's bytes: twice the pages a budget holds), each in place. A CPU rasterizer waits at every
//! barrier and pays for every scope and dispatch (104 tiles of no triangles storing 16 slots
//! each took 4.1–4.9 ms in batches of 4 tiles, 1.4–2.1 in batches of 8, where copying D32
//! slots took 0.9–1.1); yet a larger scope was slower again: 6² tiles rendered a third fewer
//! tiles a frame than 3² (146 against 217–226 at the `asm` scene's grating at 16 MiB;
//! llvmpipe, 2 Zen 3 cores). So a batch is `SCRATCH_SIDE`² tiles in one rendering scope, and
//! the scratch has layers, a batch each ([`scratch_layers`]): the packing waits for every tile
//! drawn before it, but the batches between two packings are scopes of their own, and
//! llvmpipe bins one while it rasterizes the one before (4 layers: 20–29 % more tiles in the
//! same milliseconds; one scope of as many tiles bins them all before it rasterizes any). The
//! scratch counts in the budget.
//!
//! The polygon-ID test keeps a second buffer of pages, of IDs, in the same page order, filled
//! from an ID scratch laid out as the depth one.
use super::page_table::MAX_PAGES;
use super::pool::{DEPTH_PAGE_BYTES, PAGE_ID_BYTES, SLOT_SIDE, TILE_PAGES};
use super::tile::TileKey;
use crate::backend::{
    Binding, BindingKind, Buffer, BufferDesc, BufferUsage, Cmd, ComputePipeline, Context, Depth, DepthTest,
    Edge, Format, GraphicsDesc, GraphicsPipeline, Image, ImageDesc, ImageUsage, Sampler, Target, TexelBuffer,
    Topology,
};
use crate::error::{Error, Result};
use crate::frame::gpu_scene::MESH_POSITIONS;
use crate::frame::shadow_depth::ShadowMaps;
use crate::frame::{GpuScene, DEPTH_FORMAT};
use crate::layouts::constants::{ASM_PACK_GROUP, ASM_PAGE_TEXELS, ASM_TILE_TEXELS};
use crate::layouts::{bytes_of, spirv, AsmPackPush, AsmTilePush};
use glam::Mat4;
use gpu_allocator::MemoryLocation;
use std::sync::Arc;

/// The ID test's polygon IDs.
const ID_FORMAT: Format = Format::R32_UINT;
/// Tiles a side of a layer of the scratch: 9 tiles a batch.
const SCRATCH_SIDE: u32 = 3;
/// Tiles a batch renders: a layer of the scratch.
const BATCH_TILES: usize = (SCRATCH_SIDE * SCRATCH_SIDE) as usize;
/// Slots of a layer of the scratch.
const LAYER_SLOTS: u64 = (SCRATCH_SIDE * SCRATCH_SIDE) as u64 * TILE_PAGES;
/// The most layers of the scratch: past 8 a packing's wait is spread over 72 tiles or more.
const MAX_SCRATCH_LAYERS: u32 = 8;
/// Budget bytes per layer of the scratch: 4 MiB, whose pages are short (a second layer, 145 KiB
/// of pages, left more pixels misclassified at rest), keeps one.
const BUDGET_PER_LAYER: u64 = 4 << 20;
/// Bytes of a slot of the D32 depth scratch (and of the ID scratch).
const SLOT_TEXEL_BYTES: u64 = 4 * ASM_PAGE_TEXELS as u64 * ASM_PAGE_TEXELS as u64;
/// Bytes of a slot's entry in the packing's list: the slot and its page.
const SLOT_ENTRY_BYTES: u64 = 8;

/// Bytes of a scratch of `layers` layers for pages of `page_bytes`: per slot its D32 depth (and
/// with the ID test, whose pages are larger, its IDs) and its entry in the packing's list.
pub fn scratch_bytes(page_bytes: u64, layers: u32) -> u64 {
    let ids = u64::from(page_bytes > DEPTH_PAGE_BYTES);
    u64::from(layers) * LAYER_SLOTS * (SLOT_TEXEL_BYTES * (1 + ids) + SLOT_ENTRY_BYTES)
}

/// The scratch's layers under a budget of `budget` bytes: one per `BUDGET_PER_LAYER`, at least
/// one and at most `MAX_SCRATCH_LAYERS` (16 MiB: 4 layers, 0.57 MiB; 1.13 with the ID test).
pub fn scratch_layers(budget: u64) -> u32 {
    (budget / BUDGET_PER_LAYER).clamp(1, u64::from(MAX_SCRATCH_LAYERS)) as u32
}

/// A tile render of this frame (`super::pool::PageOp`): the square of `key`, its slots
/// `stores` names stored in their pages.
#[derive(Clone)]
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
    pages: TexelBuffer,
    scratch: Image,
    /// Renders a tile's depth and IDs.
    tile: GraphicsPipeline,
    /// Each mesh's first ID (by group, then mesh).
    first: Vec<Vec<u32>>,
}

pub struct PageStore {
    pages: u32,
    /// Batches between two packings: the scratch's layers.
    layers: u32,
    /// The depth pages, as `asm_pack.comp` lays them out.
    depth: TexelBuffer,
    /// Tiles of depth, rendered with the shadow-depth pipeline.
    scratch: ShadowMaps,
    /// The slots of the scratch a packing packs (`asm_pack.comp`).
    slots: Buffer,
    pack: ComputePipeline,
    ids: Option<IdPages>,
    /// Reads the scratch in the packing.
    nearest: Sampler,
}

impl PageStore {
    /// `pages` pages (the budget's share, [`super::memory::AsmMemory::within`]) and a scratch
    /// of `layers` layers; with polygon IDs when `ids`.
    pub fn new(ctx: &Arc<Context>, gpu: &GpuScene, pages: u32, layers: u32, ids: bool) -> Result<PageStore> {
        if pages >= MAX_PAGES {
            return Err(Error::InvalidArgument(format!(
                "an ASM budget of {pages} pages: the page table indexes fewer than {MAX_PAGES}"
            )));
        }
        let buffer = |name, page_bytes| {
            TexelBuffer::new(ctx, name, u64::from(pages) * page_bytes, MemoryLocation::GpuOnly).map_err(|e| {
                match e {
                    Error::OutOfDeviceMemoryFor { reason, .. } => {
                        Error::InvalidArgument(format!("an ASM budget of {pages} pages: {reason}"))
                    }
                    e => e,
                }
            })
        };
        let depth = buffer("asm.pages", DEPTH_PAGE_BYTES)?;
        let ids = match ids {
            true => Some(IdPages::new(ctx, gpu, buffer("asm.id_pages", PAGE_ID_BYTES)?, layers)?),
            false => None,
        };
        let storage = |name, size, usage| {
            Buffer::new(ctx, &BufferDesc { name, size, usage, location: MemoryLocation::GpuOnly })
        };
        let pack = ComputePipeline::new(
            ctx,
            "asm.pack",
            spirv::ASM_PACK_COMP,
            &[BindingKind::SampledImage, BindingKind::StorageBuffer, BindingKind::StorageTexelBuffer],
            size_of::<AsmPackPush>() as u32,
        )?;
        let slots = u64::from(layers) * LAYER_SLOTS;
        Ok(PageStore {
            pages,
            layers,
            depth,
            scratch: ShadowMaps::new(ctx, "asm.scratch", SCRATCH_SIDE * ASM_TILE_TEXELS, layers)?,
            slots: storage(
                "asm.pack_slots",
                slots * SLOT_ENTRY_BYTES,
                BufferUsage::STORAGE | BufferUsage::TRANSFER_DST,
            )?,
            pack,
            ids,
            nearest: Sampler::new(ctx, "asm.scratch_sampler", false, Edge::Clamp, Edge::Clamp)?,
        })
    }

    /// Pages the store holds.
    pub fn pages(&self) -> u32 {
        self.pages
    }

    /// Tiles rendered between two packings: a batch in each layer of the scratch.
    pub fn packing_tiles(&self) -> usize {
        BATCH_TILES * self.layers as usize
    }

    /// The depth pages as the lookups read them.
    pub fn depth_binding(&self) -> Binding<'_> {
        Binding::Texel(&self.depth)
    }

    /// The ID pages as the lookups read them, for the ID test.
    pub fn id_binding(&self) -> Option<Binding<'_>> {
        self.ids.as_ref().map(|ids| Binding::Texel(&ids.pages))
    }

    /// The polygon ID of the first triangle of mesh `mesh` of group `group` (0 without IDs).
    pub fn first_id(&self, group: usize, mesh: usize) -> u32 {
        self.ids.as_ref().map_or(0, |ids| ids.first[group][mesh])
    }

    /// Records `writes` in order, one debug label each: a batch a layer of the scratch, and a
    /// packing when every layer is drawn.
    pub fn record(&self, ctx: &Context, cmd: Cmd, scene: &GpuScene, writes: &[TileWrite]) {
        for packing in writes.chunks(self.packing_tiles()) {
            // Slots of the scratch to store (numbered layer after layer), with their pages.
            let mut squares: Vec<(u32, u32)> = Vec::new();
            for (layer, batch) in packing.chunks(BATCH_TILES).enumerate() {
                let layer = layer as u32;
                self.begin_batch(ctx, cmd, layer);
                let first_slot = layer * LAYER_SLOTS as u32;
                for (i, write) in batch.iter().enumerate() {
                    let key = write.key;
                    ctx.begin_label(cmd, &format!("asm_tile L{} ({}, {})", key.level, key.x, key.y));
                    let (x, y) = (i as u32 % SCRATCH_SIDE, i as u32 / SCRATCH_SIDE);
                    ctx.restrict_to_square(cmd, [x * ASM_TILE_TEXELS, y * ASM_TILE_TEXELS], ASM_TILE_TEXELS);
                    self.draw_tile(ctx, cmd, scene, write);
                    for &(slot, page) in &write.stores {
                        let (sx, sy) = (x * SLOT_SIDE + slot % SLOT_SIDE, y * SLOT_SIDE + slot / SLOT_SIDE);
                        squares.push((first_slot + sx + sy * SCRATCH_SIDE * SLOT_SIDE, page));
                    }
                    ctx.end_label(cmd);
                }
                ctx.end_rendering(cmd);
            }
            self.store(ctx, cmd, &squares);
        }
    }

    /// Opens the rendering scope of a batch: `layer` of the scratch cleared, depth and IDs for
    /// the ID test.
    fn begin_batch(&self, ctx: &Context, cmd: Cmd, layer: u32) {
        let Some(ids) = &self.ids else { return self.scratch.begin(ctx, cmd, layer) };
        let color = Target { image: &ids.scratch, layer };
        ctx.begin_rendering(cmd, Some(color), Some([0.0; 4]), Some(Depth::Clear(self.scratch.target(layer))));
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

    /// Packs slots of the scratch into their pages (and copies their IDs). A page written twice
    /// keeps the later slot: a slot given back by a tile and taken by another rendered after it
    /// in the same packing.
    fn store(&self, ctx: &Context, cmd: Cmd, pending: &[(u32, u32)]) {
        let mut seen = rustc_hash::FxHashSet::default();
        let squares: Vec<(u32, u32)> =
            pending.iter().rev().filter(|(_, page)| seen.insert(*page)).copied().collect();
        if squares.is_empty() {
            return;
        }
        let slots: Vec<u8> =
            squares.iter().flat_map(|&(slot, page)| [slot, page]).flat_map(u32::to_ne_bytes).collect();
        self.slots.record_update(cmd, 0, &slots);
        // The scratch's depths drawn and the list written before the packing reads them.
        ctx.full_barrier(cmd);
        let count = squares.len() as u32;
        let push = AsmPackPush { count: [count, 0, 0, 0] };
        let bindings = [
            Binding::Sampled(self.scratch.image(), &self.nearest),
            Binding::Storage(&self.slots),
            Binding::StorageTexel(&self.depth),
        ];
        self.pack.dispatch(cmd, &bindings, bytes_of(&push), [count.div_ceil(ASM_PACK_GROUP), 1, 1]);
        if let Some(ids) = &self.ids {
            let page_at = |page: u32| u64::from(page) * PAGE_ID_BYTES;
            let side = SCRATCH_SIDE * SLOT_SIDE;
            let from = |slot: u32| {
                let (layer, slot) = (slot / LAYER_SLOTS as u32, slot % LAYER_SLOTS as u32);
                [slot % side * ASM_PAGE_TEXELS, slot / side * ASM_PAGE_TEXELS, layer]
            };
            let squares: Vec<([u32; 3], u64)> =
                squares.iter().map(|&(slot, page)| (from(slot), page_at(page))).collect();
            ids.scratch.record_copy_squares_to(cmd, ids.pages.buffer(), &squares, ASM_PAGE_TEXELS);
        }
        // Read before the next packing's renders and list overwrite the scratch and the list.
        ctx.full_barrier(cmd);
    }
}

impl IdPages {
    fn new(ctx: &Arc<Context>, gpu: &GpuScene, pages: TexelBuffer, layers: u32) -> Result<IdPages> {
        let usage = ImageUsage::COLOR_ATTACHMENT | ImageUsage::TRANSFER_SRC;
        let desc = ImageDesc::square_array(
            "asm.id_scratch",
            SCRATCH_SIDE * ASM_TILE_TEXELS,
            layers,
            ID_FORMAT,
            usage,
        );
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
        Ok(IdPages { pages, scratch: Image::new(ctx, &desc)?, tile, first })
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::layouts::constants::{ASM_PAGE_DEPTH_TEXELS, ASM_PAGE_ID_TEXELS};
    use crate::techniques::asm::pool::ID_PAGE_BYTES;

    /// asm_pack.comp and asm_lookup.glsl read a depth page as 16-byte texels: a slot's 16-bit
    /// depths eight to a texel, then one texel for the span; an ID page four IDs to a texel.
    #[test]
    fn a_page_holds_its_slot_as_the_shaders_lay_it_out() {
        let slot_texels = u64::from(ASM_PAGE_TEXELS * ASM_PAGE_TEXELS);
        assert_eq!(u64::from(ASM_PAGE_DEPTH_TEXELS - 1) * 8, slot_texels);
        assert_eq!(DEPTH_PAGE_BYTES, 2 * slot_texels + 16);
        assert_eq!(u64::from(ASM_PAGE_ID_TEXELS) * 4, slot_texels);
        assert_eq!(PAGE_ID_BYTES, SLOT_TEXEL_BYTES);
        // The scratch: a D32 depth (and ID) per texel of its slots and a list entry (slot,
        // page) per slot.
        assert_eq!(scratch_bytes(DEPTH_PAGE_BYTES, 1), LAYER_SLOTS * (1024 + 8));
        assert_eq!(scratch_bytes(ID_PAGE_BYTES, 3), 3 * LAYER_SLOTS * (2048 + 8));
    }

    /// A layer per 4 MiB: none beyond the first at 4 MiB, whose pages are short, 4 at 16 MiB
    /// (3.5 % of it), never more than 8.
    #[test]
    fn the_scratch_takes_a_layer_per_4_mib() {
        let mib = 1u64 << 20;
        for (budget, layers) in [(mib, 1), (4 * mib, 1), (8 * mib, 2), (16 * mib, 4), (256 * mib, 8)] {
            assert_eq!(scratch_layers(budget), layers, "{budget} bytes");
            assert!(scratch_bytes(DEPTH_PAGE_BYTES, layers) * 28 <= budget.max(4 * mib));
        }
    }
}
