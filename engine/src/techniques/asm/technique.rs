//! The adaptive shadow maps technique (`--technique asm`): one spot or point light, its view a
//! quadtree of tiles in a page pool under a byte budget, refined every frame where the eye sees
//! shadow edges at a coarser resolution than its pixels.
//!
//! A frame follows the paper's order: the eye view is analysed first, and the tiles it asks for
//! are rendered before the same frame looks them up. Two submissions:
//! 1. analysis: `asm_refresh` re-renders the resident tiles a moving group touched (see below),
//!    `depth_prepass` draws the scene's depth from the eye (the lighting pass shades over it),
//!    and `asm_analysis` finds, per eye pixel (one of each 2×2 block per frame, in turn), the
//!    tile it uses, and on shadow edges short of resolution the chain of finer tiles it asks
//!    for, counted in a buffer;
//! 2. the host reads the counts, marks the used tiles, and plans within the time budget
//!    (`plan`); then the frame: `asm_tiles` renders the planned tiles, each depth-only into its
//!    page with the light's projection cropped to its square (one debug label per tile), and
//!    `scene` shades with each point's visibility looked up in the finest resident tile holding
//!    it (the page table's directory and descent).
//!
//! The light's view and lighting are the shadowmap technique's (`shadow_light`, the same bias),
//! so the two compare pixel by pixel. Invalidation: the light's record changing (it moved or
//! the scene's depth range did) drops every tile and renders the root again; a group moving
//! re-renders the resident tiles its old or new light-uv bounds overlap (outside the time
//! budget: a stale tile would show the group where it was), and keeps the others as they are.
//! Dropping them instead would cut the quadtree: every ancestor of a refined tile overlaps a
//! group somewhere in its square.
use super::light_view::{tile_view_proj, UvRect};
use super::page_table;
use super::plan::{plan, rescaled, CostModel, Request};
use super::pool::{Insert, PagePool, DEPTH_PAGE_BYTES, ID_PAGE_BYTES};
use super::tile::TileKey;
use crate::backend::{
    vk, Binding, BindingKind, Buffer, BufferDesc, ComputePipeline, Context, Depth, DepthTest, Edge,
    GraphicsDesc, GraphicsPipeline, Image, ImageDesc, MemoryLocation, Sampler, Target, FRAGMENT_STORES,
    GEOMETRY_SHADER,
};
use crate::error::{Error, Result};
use crate::layouts::{bytes_of, constants, spirv, AsmAnalysisPush, AsmTilePush, LocalDrawPush, ShadowLight};
use crate::pass::{FrameExecutor, Pass, PassTiming};
use crate::renderer::{GpuMesh, GpuScene, DEPTH_FORMAT};
use crate::scene::{Light, Scene};
use crate::techniques::parallel_lights::scene_sphere;
use crate::techniques::scene_pass::{
    depth_prepass, depth_prepass_pipeline, scene_pass, scene_pipeline, PREPASS_SCENE_READS,
};
use crate::techniques::shadow_depth::ShadowMaps;
use crate::techniques::shadow_map::{shadow_light, DEPTH_BIAS};
use crate::techniques::tamura::occlusion::{group_bounds, GroupBounds};
use crate::techniques::unshadowed::MESH_POSITIONS;
use crate::techniques::{FrameInputs, FrameState, Technique};
use glam::{Mat4, Vec3};
use std::sync::Arc;

/// Bytes in a megabyte of `--asm-budget-mb` (MiB, as the paper's 16 MB for a 2048² D32 map).
pub const MB: u64 = 1 << 20;

/// The shadow test of the lookup. The bias test is the default: at equal memory it holds twice
/// the tiles, and over the `asm` walkthrough's close-ups it misclassified fewer pixels (IDs
/// only won on the bunny, whose surfaces turn away from the light; BENCHMARKS.md).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum AsmTest {
    /// The paper's: a tile texel holding the receiver's own polygon is lit; otherwise the
    /// depth comparison with bias decides. Pages hold an ID per texel beside the depth.
    Id,
    /// The depth comparison with the shadowmap technique's slope-scaled bias alone.
    #[default]
    Bias,
}

impl AsmTest {
    /// Bytes of one page of the pool.
    pub fn page_bytes(self) -> u64 {
        match self {
            AsmTest::Id => ID_PAGE_BYTES,
            AsmTest::Bias => DEPTH_PAGE_BYTES,
        }
    }
}

/// The technique's parameters.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct AsmSettings {
    /// The page pool's budget, MB: it never holds more tiles than fit.
    pub budget_mb: f64,
    /// Per-frame time budget of tile rendering, ms, against the calibrated cost model.
    pub time_ms: f64,
    pub test: AsmTest,
}

impl Default for AsmSettings {
    fn default() -> Self {
        // 32 ms: some 30 64² tiles per frame on lavapipe, with the scene's 5,000 triangles; at
        // 8 ms the walkthrough of BENCHMARKS.md misclassified 17 % more pixels at 16 MiB.
        AsmSettings { budget_mb: 16.0, time_ms: 32.0, test: AsmTest::default() }
    }
}

impl AsmSettings {
    pub fn validated(self) -> Result<AsmSettings> {
        let bytes = self.budget_mb * MB as f64;
        if !(bytes >= self.test.page_bytes() as f64 && bytes.is_finite()) {
            return Err(Error::InvalidArgument(format!(
                "an ASM budget of {} MB holds no tile: a tile takes {} KiB",
                self.budget_mb,
                self.test.page_bytes() / 1024
            )));
        }
        if !(self.time_ms > 0.0 && self.time_ms.is_finite()) {
            return Err(Error::InvalidArgument(format!(
                "the ASM time budget {} ms must be positive",
                self.time_ms
            )));
        }
        Ok(self)
    }

    pub fn budget_bytes(&self) -> u64 {
        (self.budget_mb * MB as f64) as u64
    }
}

/// What the hierarchy holds after a frame's update, for measurements.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct AsmStats {
    pub budget_bytes: u64,
    /// Bytes of the resident tiles' pages (never above the budget).
    pub bytes_used: u64,
    pub resident_tiles: usize,
    /// The finest resident level (0: the root alone).
    pub deepest_level: u32,
    /// Tiles rendered this frame, in render order.
    pub rendered: Vec<TileKey>,
    /// The cost model fitted at start-up: ms per triangle and per tile.
    pub cost: (f64, f64),
}

struct TileIds {
    image: Image,
    pipeline: GraphicsPipeline,
    first: Vec<Vec<u32>>,
}

/// A tile to render this frame.
struct TileRender {
    key: TileKey,
    page: u32,
    view_proj: Mat4,
    /// Per group: whether its light-uv bounds overlap the tile (else it is not drawn).
    groups: Vec<bool>,
}

pub struct Asm {
    light: Light,
    bounds: Vec<GroupBounds>,
    /// Triangles of each group.
    triangles: Vec<u64>,
    settings: AsmSettings,
    pool: PagePool,
    /// The page pool: one D32 layer of `ASM_TILE_TEXELS`² per page.
    tiles: ShadowMaps,
    /// The ID test's polygon IDs: an R32_UINT layer per page, the pipeline that renders depth
    /// and IDs, and each mesh's first ID (by group, then mesh).
    ids: Option<TileIds>,
    prepass_pipeline: GraphicsPipeline,
    scene_pipeline: GraphicsPipeline,
    analysis: ComputePipeline,
    nearest: Sampler,
    /// `ShadowLight` records (the light in record 0), as the shadowmap technique's.
    records: Buffer,
    /// The page table (page_table::PageTable): the directory, then `AsmNode` per resident tile.
    table: Buffer,
    /// What `asm_analysis` writes (see `AsmAnalysisPush`), read by `analysed`.
    requests: Buffer,
    /// Per page-table node, the last frame whose lighting looked a point up in its tile.
    used: Buffer,
    /// The tile of each node of the page table the last lighting pass descended.
    lit_keys: Vec<TileKey>,
    /// The start-up calibration's model.
    cost: CostModel,
    /// What the tiles of recent frames took over what `cost` predicted (geometric mean).
    cost_scale: f64,
    /// What `cost` predicts for this frame's planned tiles, ms.
    planned_ms: f64,
    frame: u64,
    /// The light record, group transforms and group light-uv bounds of the frame.
    record: Option<ShadowLight>,
    transforms: Vec<Mat4>,
    group_rects: Vec<UvRect>,
    /// The tile of each node of the page table the analysis descends.
    table_keys: Vec<TileKey>,
    /// Resident tiles a moving group made stale, rendered before the analysis.
    refresh: Vec<TileRender>,
    /// Tiles the analysis asked for, rendered before the lighting.
    render: Vec<TileRender>,
    stats: AsmStats,
}

/// The ID test's polygon IDs.
const ID_FORMAT: vk::Format = vk::Format::R32_UINT;

/// Tiles the analysis may ask for under one page-table node: 4 + 16 + ... down to
/// `ASM_CHAIN_LEVELS` (as asm_analysis.comp's `ASM_REQUEST_SLOTS`).
const REQUEST_SLOTS: usize = ((1 << (2 * constants::ASM_CHAIN_LEVELS + 2)) - 4) / 3;
/// Uints of the analysis output per page-table node: a used flag, an edge count and a sum of
/// missing levels per slot.
const REQUEST_WORDS: u64 = 1 + 2 * REQUEST_SLOTS as u64;

impl Asm {
    pub fn new(ctx: &Arc<Context>, scene: &Scene, gpu: &GpuScene, settings: AsmSettings) -> Result<Asm> {
        let settings = settings.validated()?;
        let [light] = scene.lights[..] else {
            return Err(Error::InvalidArgument(format!(
                "the asm technique shadows exactly one point or spot light; scene {} has {}",
                scene.name,
                scene.lights.len()
            )));
        };
        if !ctx.info().has(FRAGMENT_STORES) {
            return Err(Error::Unsupported(format!(
                "the asm technique needs {FRAGMENT_STORES} on {}",
                ctx.info().name
            )));
        }
        let pool = PagePool::new(settings.budget_bytes(), settings.test.page_bytes())?;
        let capacity = pool.capacity();
        let tiles =
            ShadowMaps::new(ctx, "asm", constants::ASM_TILE_TEXELS, capacity).map_err(|e| match e {
                Error::InvalidArgument(e) => Error::InvalidArgument(format!(
                    "an ASM budget of {} MB is {capacity} pages, one image layer each: {e}",
                    settings.budget_mb
                )),
                e => e,
            })?;
        let ids = match settings.test {
            AsmTest::Bias => None,
            AsmTest::Id => Some(TileIds::new(ctx, gpu, capacity)?),
        };
        let mut bindings = vec![
            BindingKind::UniformBuffer,
            BindingKind::UniformBuffer,
            BindingKind::SampledImage,
            BindingKind::StorageBuffer,
            BindingKind::StorageBuffer,
        ];
        let fragment = match settings.test {
            AsmTest::Bias => spirv::ASM_LIGHTS_FRAG,
            AsmTest::Id => {
                bindings.push(BindingKind::SampledImage);
                spirv::ASM_LIGHTS_ID_FRAG
            }
        };
        let scene_pipeline = scene_pipeline(
            ctx,
            "scene_asm_lights",
            (spirv::LOCAL_LIGHTS_VERT, fragment),
            &bindings,
            size_of::<LocalDrawPush>(),
            DepthTest::Equal,
        )?;
        let analysis = ComputePipeline::new(
            ctx,
            "asm_analysis",
            spirv::ASM_ANALYSIS_COMP,
            &[
                BindingKind::UniformBuffer,
                BindingKind::UniformBuffer,
                BindingKind::SampledImage,
                BindingKind::StorageBuffer,
                BindingKind::SampledImage,
                BindingKind::StorageBuffer,
            ],
            size_of::<AsmAnalysisPush>() as u32,
        )?;
        let buffer =
            |name, size, usage, location| Buffer::new(ctx, &BufferDesc { name, size, usage, location });
        let records = buffer(
            "asm.lights",
            u64::from(constants::MAX_LOCAL_LIGHTS) * size_of::<ShadowLight>() as u64,
            vk::BufferUsageFlags::UNIFORM_BUFFER,
            MemoryLocation::CpuToGpu,
        )?;
        let table = buffer(
            "asm.page_table",
            page_table::PageTable::buffer_bytes(capacity),
            vk::BufferUsageFlags::STORAGE_BUFFER,
            MemoryLocation::CpuToGpu,
        )?;
        let requests = buffer(
            "asm.requests",
            REQUEST_WORDS * u64::from(capacity) * 4,
            vk::BufferUsageFlags::STORAGE_BUFFER | vk::BufferUsageFlags::TRANSFER_DST,
            MemoryLocation::GpuToCpu,
        )?;
        let used = buffer(
            "asm.used",
            u64::from(capacity) * 4,
            vk::BufferUsageFlags::STORAGE_BUFFER,
            MemoryLocation::GpuToCpu,
        )?;
        let triangles = (0..scene.groups.len())
            .map(|g| gpu.meshes.iter().filter(|m| m.group == g).map(|m| u64::from(m.index_count / 3)).sum())
            .collect();
        let mut asm = Asm {
            light,
            bounds: group_bounds(scene),
            triangles,
            settings,
            pool,
            tiles,
            ids,
            prepass_pipeline: depth_prepass_pipeline(ctx, "asm.depth_prepass", size_of::<LocalDrawPush>())?,
            scene_pipeline,
            analysis,
            nearest: Sampler::new(ctx, "asm.eye_depth_sampler", false, Edge::Clamp, Edge::Clamp)?,
            records,
            table,
            requests,
            used,
            lit_keys: Vec::new(),
            cost: CostModel { ms_per_triangle: 0.0, ms_per_tile: 1.0 },
            cost_scale: 1.0,
            planned_ms: 0.0,
            frame: 0,
            record: None,
            transforms: Vec::new(),
            group_rects: Vec::new(),
            table_keys: Vec::new(),
            refresh: Vec::new(),
            render: Vec::new(),
            stats: AsmStats::default(),
        };
        asm.cost = asm.calibrate(ctx, gpu)?;
        Ok(asm)
    }

    /// The cost model a·N + b of a tile render, fitted to timed renders of tiles drawing
    /// different numbers of triangles on this device (the root, and tiles of levels 1 to 3
    /// along the view's diagonals), each rendered twice and the second timing kept (the first
    /// pays for cold caches). Without timestamps the model stays at 1 ms per tile.
    fn calibrate(&self, ctx: &Arc<Context>, gpu: &GpuScene) -> Result<CostModel> {
        if ctx.info().timestamp_period_ns.is_none() {
            return Ok(self.cost);
        }
        let (centre, radius) = scene_sphere(&self.bounds, &gpu.transforms);
        let record = shadow_light(&self.light, centre, radius, constants::ASM_TILE_TEXELS);
        let view_proj = Mat4::from_cols_array_2d(&record.view_proj);
        let rects = self.group_rects_for(&view_proj, &gpu.transforms);
        let mut keys = vec![TileKey::ROOT];
        for level in 1..=3u32 {
            let n = 1 << level;
            keys.extend([(0, 0), (n - 1, n - 1), (n / 2, n / 2 - 1), (0, n - 1)].map(|(x, y)| TileKey {
                level,
                x,
                y,
            }));
        }
        let renders: Vec<TileRender> =
            keys.iter().map(|&k| self.tile_render(k, 0, &view_proj, &rects)).collect();
        let mut executor = FrameExecutor::new(ctx, "asm.calibration")?;
        let mut samples = Vec::new();
        for round in 0..2 {
            let passes = renders
                .iter()
                .map(|t| {
                    Pass::new("asm_calibration", &[], &["asm_calibration"], move |cmd| {
                        self.record_tile(ctx, cmd, gpu, t)
                    })
                })
                .collect();
            let timings = executor.run(&[], passes)?;
            if round == 1 {
                for (t, timing) in renders.iter().zip(timings) {
                    samples.push((self.tile_triangles(&t.groups), timing.gpu_ms.unwrap_or(0.0)));
                }
            }
        }
        Ok(CostModel::fit(&samples))
    }

    /// Records the renders of `tiles`, one debug label each.
    fn record_tiles(&self, ctx: &Context, cmd: vk::CommandBuffer, scene: &GpuScene, tiles: &[TileRender]) {
        for t in tiles {
            ctx.begin_label(cmd, &format!("asm_tile L{} ({}, {})", t.key.level, t.key.x, t.key.y));
            self.record_tile(ctx, cmd, scene, t);
            ctx.end_label(cmd);
        }
    }

    /// Records the render of one tile into its page (and its ID layer for the ID test).
    fn record_tile(&self, ctx: &Context, cmd: vk::CommandBuffer, scene: &GpuScene, t: &TileRender) {
        let Some(ids) = &self.ids else {
            return self.tiles.record(ctx, cmd, scene, t.page, &t.view_proj, |m| t.groups[m.group]);
        };
        let (color, depth) = (Target { image: &ids.image, layer: t.page }, self.tiles.target(t.page));
        ctx.begin_rendering(cmd, Some(color), Some([0.0; 4]), Some(Depth::Clear(depth)));
        ids.pipeline.bind(cmd, &[]);
        for mesh in scene.meshes.iter().filter(|m| t.groups[m.group]) {
            let push = AsmTilePush {
                transform: (t.view_proj * scene.transforms[mesh.group]).to_cols_array_2d(),
                ids: [ids.first[mesh.group][mesh.mesh], 0, 0, 0],
            };
            ids.pipeline.push(cmd, bytes_of(&push));
            ctx.draw_indexed(cmd, &[&mesh.vertices], &mesh.indices, mesh.index_count);
        }
        ctx.end_rendering(cmd);
    }

    /// Each group's light-uv bounds under `transforms`.
    fn group_rects_for(&self, view_proj: &Mat4, transforms: &[Mat4]) -> Vec<UvRect> {
        self.bounds
            .iter()
            .zip(transforms)
            .map(|(b, t)| {
                let (mut lo, mut hi) = (Vec3::INFINITY, Vec3::NEG_INFINITY);
                for corner in 0..8 {
                    let pick = |bit: usize, a: f32, b: f32| if corner >> bit & 1 == 0 { a } else { b };
                    let local = Vec3::new(
                        pick(0, b.min.x, b.max.x),
                        pick(1, b.min.y, b.max.y),
                        pick(2, b.min.z, b.max.z),
                    );
                    let world = t.transform_point3(local);
                    (lo, hi) = (lo.min(world), hi.max(world));
                }
                UvRect::of_box(view_proj, lo, hi)
            })
            .collect()
    }

    fn tile_render(&self, key: TileKey, page: u32, view_proj: &Mat4, rects: &[UvRect]) -> TileRender {
        let square = UvRect::of_tile(key);
        TileRender {
            key,
            page,
            view_proj: tile_view_proj(view_proj, key),
            groups: rects.iter().map(|r| r.overlaps(&square)).collect(),
        }
    }

    fn tile_triangles(&self, groups: &[bool]) -> u64 {
        groups.iter().zip(&self.triangles).filter(|(drawn, _)| **drawn).map(|(_, t)| t).sum()
    }

    /// Marks the tiles the last frame's lighting and this frame's analysis looked up as used
    /// (the analysis sees the new view first), and turns the analysis' edge counts into
    /// requests.
    fn read_requests(&mut self) -> Result<Vec<Request>> {
        let last = (self.frame - 1) as u32;
        for (key, mark) in self.lit_keys.iter().zip(read_words(&self.used)?) {
            if mark == last {
                self.pool.touch(*key, self.frame);
            }
        }
        let words = read_words(&self.requests)?;
        let capacity = self.pool.capacity() as usize;
        let (counts, missing) = words[capacity..].split_at(capacity * REQUEST_SLOTS);
        let mut requests = Vec::new();
        for (node, &key) in self.table_keys.iter().enumerate() {
            if words[node] != 0 {
                self.pool.touch(key, self.frame);
            }
            // Slots row by row within each depth, as the analysis counts them.
            let mut slot = node * REQUEST_SLOTS;
            for depth in 1..=constants::ASM_CHAIN_LEVELS {
                let side = 1u32 << depth;
                for i in 0..side * side {
                    let edge_pixels = counts[slot];
                    let (x, y) = (key.x * side + i % side, key.y * side + i / side);
                    let tile = TileKey { level: key.level + depth, x, y };
                    slot += 1;
                    if edge_pixels == 0 || tile.level > constants::ASM_MAX_LEVEL {
                        continue;
                    }
                    let square = UvRect::of_tile(tile);
                    let groups: Vec<bool> = self.group_rects.iter().map(|r| r.overlaps(&square)).collect();
                    requests.push(Request {
                        key: tile,
                        edge_pixels,
                        missing_levels: missing[slot - 1],
                        triangles: self.tile_triangles(&groups),
                    });
                }
            }
        }
        Ok(requests)
    }

    /// Rebuilds the page table from the pool and uploads it.
    fn write_table(&mut self) -> Result<()> {
        let table = page_table::build(&self.pool);
        self.table_keys =
            table.nodes.iter().map(|n| TileKey { level: n.tile[1], x: n.tile[2], y: n.tile[3] }).collect();
        self.table.write(0, &table.bytes())
    }

    /// The push constants of each mesh's draw, in the depth prepass and the lighting pass.
    fn draw_push(&self) -> impl Fn(&GpuMesh, &Mat4) -> LocalDrawPush + '_ {
        // Frame numbers wrap after 2^32 frames; a stale mark then only keeps a tile a frame longer.
        let frame = self.frame as u32;
        move |mesh, model| LocalDrawPush {
            model: model.to_cols_array_2d(),
            albedo: [mesh.albedo[0], mesh.albedo[1], mesh.albedo[2], 0.0],
            params: [1, self.ids.as_ref().map_or(0, |ids| ids.first[mesh.group][mesh.mesh]), frame, 0],
            bias: DEPTH_BIAS,
        }
    }

    /// The hierarchy's state for measurements.
    pub fn stats(&self) -> AsmStats {
        self.stats.clone()
    }
}

/// A host-readable buffer's contents as native-endian words.
fn read_words(buffer: &Buffer) -> Result<Vec<u32>> {
    Ok(buffer.read()?.chunks_exact(4).map(|b| u32::from_ne_bytes([b[0], b[1], b[2], b[3]])).collect())
}

impl TileIds {
    fn new(ctx: &Arc<Context>, gpu: &GpuScene, capacity: u32) -> Result<TileIds> {
        if !ctx.info().has(GEOMETRY_SHADER) {
            return Err(Error::Unsupported(format!(
                "the ASM polygon-ID test needs {GEOMETRY_SHADER} on {}; use the bias test",
                ctx.info().name
            )));
        }
        let usage = vk::ImageUsageFlags::COLOR_ATTACHMENT | vk::ImageUsageFlags::SAMPLED;
        let desc = ImageDesc::square_array("asm.ids", constants::ASM_TILE_TEXELS, capacity, ID_FORMAT, usage);
        let pipeline = GraphicsPipeline::new(
            ctx,
            &GraphicsDesc {
                name: "asm.tile_ids",
                vertex_spirv: spirv::ASM_TILE_VERT,
                fragment_spirv: spirv::ASM_TILE_FRAG,
                bindings: &[],
                push_size: size_of::<AsmTilePush>() as u32,
                vertex_buffers: &[MESH_POSITIONS],
                topology: vk::PrimitiveTopology::TRIANGLE_LIST,
                color_formats: &[ID_FORMAT],
                depth_format: Some(DEPTH_FORMAT),
                depth: DepthTest::Less,
                additive: false,
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
        Ok(TileIds { image: Image::new(ctx, &desc)?, pipeline, first })
    }
}

impl Technique for Asm {
    fn update(&mut self, state: &FrameState) -> Result<()> {
        self.frame += 1;
        // The renderer keeps the scene's light count (Renderer::set_light replaces, never adds),
        // and `new` accepted exactly one.
        self.light = state.lights[0];
        let (centre, radius) = scene_sphere(&self.bounds, state.transforms);
        let record = shadow_light(&self.light, centre, radius, constants::ASM_TILE_TEXELS);
        let view_proj = Mat4::from_cols_array_2d(&record.view_proj);
        let rects = self.group_rects_for(&view_proj, state.transforms);
        let mut refresh = Vec::new();
        if self.record.is_none_or(|r| bytes_of(&r) != bytes_of(&record)) {
            // The light moved (or the depth range changed): every tile's depths are stale.
            self.pool = PagePool::new(self.settings.budget_bytes(), self.settings.test.page_bytes())?;
            refresh.push(TileKey::ROOT);
            // The analysis descends the new pool's table; otherwise last frame's `analysed`
            // wrote the table of the pool as it still is (refreshing tiles moves none).
            self.write_table()?;
        } else {
            let moved: Vec<UvRect> = (0..rects.len())
                .filter(|&g| self.transforms[g] != state.transforms[g])
                .flat_map(|g| [self.group_rects[g], rects[g]])
                .collect();
            let touched = |key: TileKey| moved.iter().any(|r| r.overlaps(&UvRect::of_tile(key)));
            refresh.extend(self.pool.resident().map(|(key, _)| key).filter(|&key| touched(key)));
            // Coarse levels first: the root leads.
            refresh.sort();
        }
        self.record = Some(record);
        self.transforms = state.transforms.to_vec();
        self.group_rects = rects;
        self.refresh = refresh
            .iter()
            .filter_map(|&key| {
                self.pool.page(key).map(|page| self.tile_render(key, page, &view_proj, &self.group_rects))
            })
            .collect();
        self.records.write(0, bytes_of(&record))?;
        Ok(())
    }

    fn analysis_passes<'a>(&'a self, inputs: &FrameInputs<'a>) -> Vec<Pass<'a>> {
        let (ctx, scene, targets, uniforms) = (inputs.ctx, inputs.scene, inputs.targets, inputs.uniforms);
        let refresh = Pass::new("asm_refresh", &[], &["shadow_maps"], move |cmd| {
            self.record_tiles(ctx, cmd, scene, &self.refresh);
        });
        // The eye view the analysis reads is the lighting pass' depth prepass.
        let eye_depth = depth_prepass(inputs, &self.prepass_pipeline, self.draw_push());
        let (width, height) = (targets.depth.width, targets.depth.height);
        let analysis = Pass::new(
            "asm_analysis",
            &["frame_uniforms", "shadow_maps", "depth"],
            &["asm_requests"],
            move |cmd| {
                self.requests.record_zero(cmd);
                ctx.full_barrier(cmd);
                let push = AsmAnalysisPush {
                    size: [width, height, self.pool.capacity(), (self.frame % 4) as u32],
                    bias: DEPTH_BIAS,
                };
                let group = constants::ASM_ANALYSIS_GROUP;
                self.analysis.dispatch(
                    cmd,
                    &[
                        Binding::Uniform(uniforms),
                        Binding::Uniform(&self.records),
                        self.tiles.binding(),
                        Binding::Storage(&self.table),
                        Binding::Sampled(&targets.depth, &self.nearest),
                        Binding::Storage(&self.requests),
                    ],
                    bytes_of(&push),
                    [width.div_ceil(2 * group), height.div_ceil(2 * group), 1],
                );
            },
        );
        vec![refresh, eye_depth, analysis]
    }

    fn analysed(&mut self) -> Result<()> {
        let requests = self.read_requests()?;
        let view_proj = Mat4::from_cols_array_2d(&self.record.expect("update sets the record").view_proj);
        let pool = &self.pool;
        let model = self.cost.scaled(self.cost_scale);
        let chosen = plan(requests, &model, self.settings.time_ms, |key| pool.page(key).is_some());
        let mut render = Vec::new();
        for (request, ratio) in chosen {
            // A parent evicted by an earlier insertion of this frame, or refused a page, refuses
            // its child (an error from the pool): the child waits for a later frame.
            if let Ok(Insert::Allocated { page } | Insert::Replaced { page, .. }) =
                self.pool.insert(request.key, self.frame, ratio)
            {
                render.push(self.tile_render(request.key, page, &view_proj, &self.group_rects));
            }
        }
        // A tile whose page a later insertion of this frame took is no longer resident.
        render.retain(|t| self.pool.page(t.key) == Some(t.page));
        self.planned_ms = render.iter().map(|t| self.cost.cost_ms(self.tile_triangles(&t.groups))).sum();
        self.render = render;
        self.write_table()?;
        self.lit_keys.clone_from(&self.table_keys);
        self.stats = AsmStats {
            budget_bytes: self.settings.budget_bytes(),
            bytes_used: self.pool.bytes_in_use(),
            resident_tiles: self.table_keys.len(),
            deepest_level: self.table_keys.iter().map(|k| k.level).max().unwrap_or(0),
            rendered: self.refresh.iter().chain(&self.render).map(|t| t.key).collect(),
            cost: (model.ms_per_triangle, model.ms_per_tile),
        };
        Ok(())
    }

    fn passes<'a>(&'a self, inputs: &FrameInputs<'a>) -> Vec<Pass<'a>> {
        let (ctx, scene) = (inputs.ctx, inputs.scene);
        let tiles = Pass::new("asm_tiles", &[], &["shadow_maps"], move |cmd| {
            self.record_tiles(ctx, cmd, scene, &self.render);
        });
        let mut bindings = vec![
            Binding::Uniform(inputs.uniforms),
            Binding::Uniform(&self.records),
            self.tiles.binding(),
            Binding::Storage(&self.table),
            Binding::Storage(&self.used),
        ];
        if let Some(ids) = &self.ids {
            bindings.push(Binding::Sampled(&ids.image, &self.nearest));
        }
        let lighting =
            scene_pass(inputs, &PREPASS_SCENE_READS, &self.scene_pipeline, bindings, self.draw_push());
        vec![tiles, lighting]
    }

    /// Scales the cost model by how long this frame's planned tiles took against what the
    /// start-up model predicted (`plan::rescaled`).
    fn timed(&mut self, timings: &[PassTiming]) {
        // Frames of a few tiles time mostly the pass' own overhead.
        if self.planned_ms < 4.0 * self.cost.ms_per_tile.max(0.01) {
            return;
        }
        let measured = timings.iter().find(|t| t.name == "asm_tiles").and_then(|t| t.gpu_ms);
        if let Some(ms) = measured.filter(|ms| *ms > 0.0) {
            self.cost_scale = rescaled(self.cost_scale, self.planned_ms, ms);
        }
    }

    fn asm_stats(&self) -> Option<AsmStats> {
        Some(self.stats())
    }

    /// The whole page pool, allocated up front (within the budget), whatever is resident.
    fn shadow_memory_bytes(&self) -> Option<u64> {
        Some(self.pool.bytes_allocated())
    }
}
