//! The adaptive shadow maps technique (`--technique asm`): one spot or point light, its view a
//! quadtree of tiles in a page pool under a byte budget, refined every frame where the eye sees
//! shadow edges at a coarser resolution than its pixels.
//!
//! A frame follows the paper's order: the eye view is analysed first, and the tiles it asks for
//! are rendered before the same frame looks them up. Two submissions:
//! 1. analysis: `asm_refresh` re-renders the resident tiles a moving group touched (see below),
//!    `depth_prepass` draws the scene's depth from the eye (the lighting pass shades over it),
//!    and `asm_analysis` finds, per eye pixel (one of each 2×2 block per frame, in turn), the
//!    tile it uses, and records the pixels on shadow edges short of resolution;
//! 2. the host marks the used tiles, counts the edge pixels for the slots of the chain of finer
//!    tiles each asks for (and the slots pixels whose texels come from two levels up ask of
//!    their tile's parent), ends the trials due (`pool`), and plans within the time budget
//!    (`plan`); then the frame: `asm_tiles` renders the planned tiles, each depth-only with the
//!    light's projection cropped to its square, into the pool's pages (and the slots ancestors
//!    store again when an eviction or a trial's end uncovers them; `pages`, one debug label
//!    each), and `scene` shades with each point's visibility looked up in the finest resident
//!    tile holding it (the page table's directory and descent).
//!
//! The light's view and lighting are the shadowmap technique's (`shadow_light`, the same bias),
//! so the two compare pixel by pixel. Invalidation: the light's record changing (it moved or
//! the scene's depth range did) drops every tile and renders the root again; a group moving
//! re-renders the resident tiles its old or new light-uv bounds overlap (outside the time
//! budget: a stale tile would show the group where it was), and keeps the others as they are.
//! Dropping them instead would cut the quadtree: every ancestor of a refined tile overlaps a
//! group somewhere in its square.
use super::light_view::{tile_view_proj, UvRect};
use super::memory::{self, edge_records, AsmMemory};
use super::page_table;
use super::pages::{PageStore, TileWrite};
use super::plan::{plan, rescaled, CostModel, Request};
use super::pool::{
    parent_slots, Insert, PageOp, PagePool, Slots, ANALYSIS_PHASES, DEPTH_PAGE_BYTES, ID_PAGE_BYTES,
    SLOT_SIDE, TILE_PAGES,
};
use super::tile::TileKey;
use crate::backend::{
    Binding, BindingKind, Buffer, BufferDesc, BufferUsage, ComputePipeline, Context, DepthTest, Edge,
    GraphicsPipeline, MemoryLocation, Sampler, TexelBuffer, FRAGMENT_STORES, GEOMETRY_SHADER,
};
use crate::error::{Error, Result};
use crate::frame::bounds::scene_sphere;
use crate::frame::bounds::{box_corners, group_bounds, GroupBounds};
use crate::frame::scene_pass::{depth_prepass, depth_prepass_pipeline, scene_pass, scene_pipeline};

use crate::frame::{FrameInputs, FrameState};
use crate::frame::{GpuMesh, GpuScene};

use crate::layouts::{bytes_of, constants, spirv, AsmAnalysisPush, LocalDrawPush, ShadowLight};
use crate::pass::{FrameExecutor, Pass, PassTiming};
use crate::scene::clusters::{runs, Cluster};
use crate::scene::{Light, Scene};
use crate::techniques::shadow_map::{shadow_light, DEPTH_BIAS};
use crate::techniques::{Technique, TechniqueStats};
use glam::{Mat4, Vec3};
use rustc_hash::{FxHashMap, FxHashSet};
use std::sync::Arc;
use std::time::Instant;

/// Bytes in a megabyte of `--asm-budget-mb` (MiB, as the paper's 16 MB for a 2048² D32 map).
pub const MB: u64 = 1 << 20;

/// The shadow test of the lookup. The bias test is the default: at equal memory it holds twice
/// the tiles, and over the `asm` walkthrough's close-ups it misclassified fewer pixels (IDs
/// only won on the bunny, whose surfaces turn away from the light; BENCHMARKS.md).
#[repr(u32)]
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, strum::FromRepr)]
#[cfg_attr(feature = "clap", derive(clap::ValueEnum))]
pub enum AsmTest {
    /// The paper's: a tile texel holding the receiver's own polygon is lit; otherwise the
    /// depth comparison with bias decides. Pages hold an ID per texel beside the depth.
    Id = 1,
    /// The depth comparison with the shadowmap technique's slope-scaled bias alone.
    #[default]
    Bias = 0,
}

impl AsmTest {
    /// Bytes of one page of the pool.
    pub fn page_bytes(self) -> u64 {
        match self {
            AsmTest::Id => ID_PAGE_BYTES,
            AsmTest::Bias => DEPTH_PAGE_BYTES,
        }
    }

    /// The least budget for images of `size` (width, height): the root tile's pages beside
    /// everything else the technique allocates ([`AsmMemory`]); (0, 0) gives the part no image
    /// size changes.
    pub fn least_budget_bytes(self, size: (u32, u32)) -> u64 {
        AsmMemory::of(TILE_PAGES as u32, self.page_bytes(), edge_records(size), 1).total()
    }
}

/// Most levels of refinement [`AsmSettings::extra_levels`] may ask for beyond an eye pixel's.
pub const MAX_EXTRA_LEVELS: u32 = 8;

/// The passes that render tiles: the resident tiles a moving group made stale, then the planned
/// ones. The other passes' time is what [`AsmTimeBudget::time_share`] takes a share of.
const REFRESH_PASS: &str = "asm_refresh";
const TILES_PASS: &str = "asm_tiles";
pub const TILE_PASSES: [&str; 2] = [REFRESH_PASS, TILES_PASS];

/// Largest [`AsmTimeBudget::time_share`]: tile renders up to a hundred times the rest of a frame.
pub const MAX_TIME_SHARE: f64 = 100.0;

/// The technique's parameters, each defined here once: the command line takes them as its
/// `--asm-*` options (these comments are their help) and the C ABI as `kage_technique_desc`'s
/// `asm_*` fields.
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(feature = "clap", derive(clap::Args))]
pub struct AsmSettings {
    /// Adaptive shadow maps: the page pool's budget, MB (MiB); never exceeded.
    #[cfg_attr(feature = "clap", arg(long = "asm-budget-mb", value_name = "MB", default_value_t = AsmSettings::default().budget_mb))]
    pub budget_mb: f64,
    #[cfg_attr(feature = "clap", command(flatten))]
    pub time: AsmTimeBudget,
    /// Adaptive shadow maps: the shadow test, `id` (the paper's polygon IDs, depth with bias
    /// as fallback; pages take twice the bytes) or `bias` (depth with slope-scaled bias).
    #[cfg_attr(feature = "clap", arg(long = "asm-test", value_enum, default_value_t = AsmSettings::default().test))]
    pub test: AsmTest,
    /// Adaptive shadow maps: levels of refinement asked for at shadow edges beyond the one
    /// whose texels match the eye pixel, 0 to 8: each halves the edge's texels and may take up
    /// to four times their pages (BENCHMARKS.md: 5 is better than 4 at 256 MiB, no better at 4
    /// and 16 MiB, where the pages run out first; 6 better still at 256 MiB, worse at 4).
    #[cfg_attr(feature = "clap", arg(long = "asm-extra-levels", value_name = "LEVELS", default_value_t = AsmSettings::default().extra_levels))]
    pub extra_levels: u32,
}

/// How long the tile renders of a frame may take: the lesser of a time and a share of the rest
/// of the frame.
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(feature = "clap", derive(clap::Args))]
pub struct AsmTimeBudget {
    /// Adaptive shadow maps: tile rendering time per frame, ms, as the start-up calibration
    /// predicts it; at most, with `--asm-time-share`.
    #[cfg_attr(feature = "clap", arg(long = "asm-time-ms", value_name = "MS", default_value_t = AsmTimeBudget::default().time_ms))]
    pub time_ms: f64,
    /// Adaptive shadow maps: tile rendering time per frame as a share of the GPU time of the
    /// frame's other passes (as the frame before took them), so that tile renders make a frame
    /// at most 1 + SHARE times as long; the lesser of this and `--asm-time-ms` (that alone on a
    /// device without timestamps, and in the first frame). Above 0, at most 100.
    #[cfg_attr(feature = "clap", arg(long = "asm-time-share", value_name = "SHARE", default_value_t = AsmTimeBudget::default().time_share))]
    pub time_share: f64,
}

impl Default for AsmTimeBudget {
    fn default() -> Self {
        // 16 ms, a 60 Hz frame: some 150 64² tiles per frame on lavapipe with the `asm` scene's
        // 5,000 triangles. It binds where the rest of a frame is longer (on lavapipe at 512²:
        // the frame 1.1–1.3x the 2048² map's, 1.35–1.55x at 32 ms, the walkthrough's error
        // while moving about 20 % higher). A share of 1: tiles at most double a frame; less
        // costs the slow walkthrough at 256² its 5x (0.5: 4.7x at 16 MiB). BENCHMARKS.md
        // "Tile time per frame".
        AsmTimeBudget { time_ms: 16.0, time_share: 1.0 }
    }
}

impl Default for AsmSettings {
    fn default() -> Self {
        AsmSettings {
            budget_mb: 16.0,
            time: AsmTimeBudget::default(),
            test: AsmTest::default(),
            extra_levels: constants::ASM_EXTRA_LEVELS,
        }
    }
}

impl AsmSettings {
    pub fn validated(self) -> Result<AsmSettings> {
        let bytes = self.budget_mb * MB as f64;
        let least = self.test.least_budget_bytes((0, 0));
        if !bytes.is_finite() {
            return Err(Error::InvalidArgument(format!(
                "an ASM budget of {} MB: the budget must be a finite number of MB",
                self.budget_mb
            )));
        }
        if bytes < least as f64 {
            return Err(Error::InvalidArgument(format!(
                "an ASM budget of {} MB holds no tile: the root tile, the scratch and the page directory take {} KiB",
                self.budget_mb,
                least / 1024
            )));
        }
        let AsmTimeBudget { time_ms, time_share } = self.time;
        if !(time_ms > 0.0 && time_ms.is_finite()) {
            return Err(Error::InvalidArgument(format!("the ASM time budget {time_ms} ms must be positive")));
        }
        if !(time_share > 0.0 && time_share <= MAX_TIME_SHARE) {
            return Err(Error::InvalidArgument(format!(
                "the ASM time share {time_share} must be above 0 and at most {MAX_TIME_SHARE}"
            )));
        }
        if self.extra_levels > MAX_EXTRA_LEVELS {
            return Err(Error::InvalidArgument(format!(
                "{} extra ASM levels: at most {MAX_EXTRA_LEVELS}",
                self.extra_levels
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
    /// Bytes of the resident tiles' pages and of everything else the technique allocated
    /// (never above the budget).
    pub bytes_used: u64,
    /// What the technique allocated, part by part (its total within the budget).
    pub memory: AsmMemory,
    pub resident_tiles: usize,
    /// The finest resident level (0: the root alone).
    pub deepest_level: u32,
    /// Tiles rendered again this frame because a moving group touched them, in render order.
    pub refreshed: Vec<TileKey>,
    /// Tiles rendered this frame for the refinement, in render order (a tile refined, or given
    /// slots back by an eviction or a trial's end).
    pub rendered: Vec<TileKey>,
    /// Tiles evicted this frame.
    pub evicted: usize,
    /// The cost model fitted at start-up: ms per triangle and per tile.
    pub cost: (f64, f64),
    /// Host ms of the last frame's planning: its update, and between the two submissions the
    /// analysis read back, the renders planned and the page table rebuilt, while the device
    /// waits (no pass timing holds it).
    pub plan_ms: f64,
}

impl AsmStats {
    /// The side of the conventional map whose texels are as fine as the deepest resident
    /// tile's (the paper reports 65,536² and 524,288² in its close-ups).
    pub fn effective_resolution(&self) -> u64 {
        u64::from(constants::ASM_TILE_TEXELS) << self.deepest_level
    }
}

pub struct Asm {
    light: Light,
    bounds: Vec<GroupBounds>,
    /// Each mesh's group and triangle clusters (`GpuMesh::clusters`), in the scene's order.
    clusters: Vec<(usize, Vec<Cluster>)>,
    settings: AsmSettings,
    pool: PagePool,
    /// The pool's pages on the GPU.
    pages: PageStore,
    prepass_pipeline: GraphicsPipeline,
    scene_pipeline: GraphicsPipeline,
    analysis: ComputePipeline,
    nearest: Sampler,
    /// `ShadowLight` records (the light in record 0), as the shadowmap technique's.
    records: Buffer,
    /// The page table (page_table::PageTable): the directory, then `AsmNode` per resident tile.
    table: TexelBuffer,
    /// What `asm_analysis` writes (see `AsmAnalysisPush`), read by `analysed`.
    requests: Buffer,
    /// The bytes of every buffer and image above, part by part.
    memory: AsmMemory,
    /// Edge records `requests` holds ([`edge_records`]).
    edge_capacity: u32,
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
    /// GPU ms of the last frame's passes other than tile renders (`time_share` of it is the
    /// tile budget), once a frame has been timed.
    other_ms: Option<f64>,
    frame: u64,
    /// The light record, group transforms, group and cluster (per mesh) light-uv bounds of the
    /// frame.
    record: Option<ShadowLight>,
    transforms: Vec<Mat4>,
    group_rects: Vec<UvRect>,
    cluster_rects: Vec<Vec<UvRect>>,
    /// The index runs of the tiles this frame renders or weighs, each found once a frame.
    draws: FrameDraws,
    /// The tile of each node of the page table the analysis descends.
    table_keys: Vec<TileKey>,
    /// Resident tiles a moving group made stale, rendered before the analysis.
    refresh: Vec<TileWrite>,
    /// Tiles the analysis asked for, and the slots evictions gave back, before the lighting.
    render: Vec<TileWrite>,
    /// Tiles evicted this frame.
    evicted: usize,
    stats: AsmStats,
    /// Requests for more slots of tiles rendered already, gathered since the frame given.
    deferred: FxHashMap<TileKey, (Request, u64)>,
    /// Host ms this frame's `update` took, for [`AsmStats::plan_ms`].
    update_ms: f64,
}

impl Asm {
    /// The technique for `scene` rendered at `size` (width, height) pixels.
    pub fn new(
        ctx: &Arc<Context>,
        scene: &Scene,
        gpu: &GpuScene,
        settings: AsmSettings,
        size: (u32, u32),
    ) -> Result<Asm> {
        let settings = settings.validated()?;
        let [light] = scene.lights[..] else {
            return Err(Error::InvalidArgument(format!(
                "the asm technique shadows exactly one point or spot light; scene {} has {} (the \
                 built-in scene asm has one)",
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
        let ids = settings.test == AsmTest::Id;
        if ids && !ctx.info().has(GEOMETRY_SHADER) {
            return Err(Error::Unsupported(format!(
                "the ASM polygon-ID test needs {GEOMETRY_SHADER} on {}; use the bias test",
                ctx.info().name
            )));
        }
        let page_bytes = settings.test.page_bytes();
        let edge_capacity = edge_records(size);
        let (most_pages, memory) = AsmMemory::within(settings.budget_bytes(), page_bytes, edge_capacity)?;
        let pages = PageStore::new(ctx, gpu, most_pages, memory.scratch_layers, ids)?;
        let pool = PagePool::new(most_pages, page_bytes)?;
        let nodes = pool.max_tiles();
        let mut bindings = vec![
            BindingKind::UniformBuffer,
            BindingKind::UniformBuffer,
            BindingKind::TexelBuffer,
            BindingKind::TexelBuffer,
            BindingKind::StorageBuffer,
        ];
        let fragment = match settings.test {
            AsmTest::Bias => spirv::ASM_LIGHTS_FRAG,
            AsmTest::Id => {
                bindings.push(BindingKind::TexelBuffer);
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
        let analysis = ComputePipeline::specialized(
            ctx,
            "asm_analysis",
            spirv::ASM_ANALYSIS_COMP,
            &[
                BindingKind::UniformBuffer,
                BindingKind::UniformBuffer,
                BindingKind::TexelBuffer,
                BindingKind::TexelBuffer,
                BindingKind::SampledImage,
                BindingKind::StorageBuffer,
            ],
            size_of::<AsmAnalysisPush>() as u32,
            &[settings.extra_levels],
        )?;
        let buffer =
            |name, size, usage, location| Buffer::new(ctx, &BufferDesc { name, size, usage, location });
        let records =
            buffer("asm.lights", memory::lights_bytes(), BufferUsage::UNIFORM, MemoryLocation::CpuToGpu)?;
        let table = TexelBuffer::new(
            ctx,
            "asm.page_table",
            page_table::PageTable::buffer_bytes(nodes),
            MemoryLocation::CpuToGpu,
        )?;
        let requests = buffer(
            "asm.requests",
            memory::requests_bytes(nodes, edge_capacity),
            BufferUsage::STORAGE | BufferUsage::TRANSFER_DST,
            MemoryLocation::GpuToCpu,
        )?;
        let mut used =
            buffer("asm.used", memory::used_bytes(nodes), BufferUsage::STORAGE, MemoryLocation::GpuToCpu)?;
        // No frame yet: a node the lighting never marked must not read as used last frame.
        used.write(0, &vec![0xFF; memory::used_bytes(nodes) as usize])?;
        let mut asm = Asm {
            light,
            bounds: group_bounds(scene),
            clusters: gpu.meshes.iter().map(|m| (m.group, m.clusters.clone())).collect(),
            settings,
            pool,
            pages,
            prepass_pipeline: depth_prepass_pipeline(ctx, "asm.depth_prepass", size_of::<LocalDrawPush>())?,
            scene_pipeline,
            analysis,
            nearest: Sampler::new(ctx, "asm.eye_depth_sampler", false, Edge::Clamp, Edge::Clamp)?,
            records,
            table,
            requests,
            memory,
            edge_capacity,
            used,
            lit_keys: Vec::new(),
            cost: CostModel { ms_per_triangle: 0.0, ms_per_tile: 1.0 },
            cost_scale: 1.0,
            planned_ms: 0.0,
            other_ms: None,
            frame: 0,
            record: None,
            transforms: Vec::new(),
            group_rects: Vec::new(),
            cluster_rects: Vec::new(),
            draws: FrameDraws::default(),
            table_keys: Vec::new(),
            refresh: Vec::new(),
            render: Vec::new(),
            evicted: 0,
            deferred: FxHashMap::default(),
            update_ms: 0.0,
            // The memory is known from the start, before the first frame's statistics.
            stats: AsmStats { memory, budget_bytes: settings.budget_bytes(), ..Default::default() },
        };
        asm.cost = asm.calibrate(ctx, gpu)?;
        Ok(asm)
    }

    /// The cost model a·N + b of a tile render, fitted to timed renders of tiles drawing
    /// different numbers of triangles on this device (the root, and tiles of levels 1 to 3
    /// along the view's diagonals), each rendered twice and the second timing kept (the first
    /// pays for cold caches), each stored into pages as a frame's tiles are (into the root's,
    /// which the first frame renders again), and each in as many renders of it as a packing
    /// takes (a batch in each layer of the scratch): a frame's renders share their packings,
    /// whose cost a tile rendered alone would pay whole. Without timestamps the model stays at
    /// 1 ms per tile.
    fn calibrate(&self, ctx: &Arc<Context>, gpu: &GpuScene) -> Result<CostModel> {
        if ctx.info().timestamp_period_ns.is_none() {
            return Ok(self.cost);
        }
        let (centre, radius) = scene_sphere(&self.bounds, &gpu.transforms);
        let record = shadow_light(&self.light, centre, radius, constants::ASM_TILE_TEXELS);
        let view_proj = Mat4::from_cols_array_2d(&record.view_proj);
        let rects = self.cluster_rects_for(&view_proj, &gpu.transforms);
        let mut keys = vec![TileKey::ROOT];
        for level in 1..=3u32 {
            let n = 1 << level;
            keys.extend([(0, 0), (n - 1, n - 1), (n / 2, n / 2 - 1), (0, n - 1)].map(|(x, y)| TileKey {
                level,
                x,
                y,
            }));
        }
        let stores = self.pool.stores(TileKey::ROOT);
        let renders: Vec<TileWrite> = keys
            .iter()
            .map(|&key| {
                let draws = tile_draws(&self.clusters, &rects, key);
                tile_write(PageOp { key, stores: stores.clone() }, &view_proj, draws)
            })
            .collect();
        let tiles = self.pages.packing_tiles();
        let batches: Vec<Vec<TileWrite>> = renders.iter().map(|t| vec![t.clone(); tiles]).collect();
        let mut executor = FrameExecutor::new(ctx, "asm.calibration")?;
        let mut samples = Vec::new();
        for round in 0..2 {
            let passes = batches
                .iter()
                .map(|b| Pass::new("asm_calibration", move |cmd| self.pages.record(ctx, cmd, gpu, b)))
                .collect();
            let timings = executor.run(passes)?;
            if round == 1 {
                for (t, timing) in renders.iter().zip(timings) {
                    samples.push((draw_triangles(&t.draws), timing.gpu_ms.unwrap_or(0.0) / tiles as f64));
                }
            }
        }
        Ok(CostModel::fit(&samples))
    }

    /// Each group's light-uv bounds under `transforms`.
    fn group_rects_for(&self, view_proj: &Mat4, transforms: &[Mat4]) -> Vec<UvRect> {
        self.bounds.iter().zip(transforms).map(|(b, t)| box_rect(view_proj, t, b.min, b.max)).collect()
    }

    /// Each mesh's clusters' light-uv bounds under `transforms`.
    fn cluster_rects_for(&self, view_proj: &Mat4, transforms: &[Mat4]) -> Vec<Vec<UvRect>> {
        let rect = |g: usize, c: &Cluster| box_rect(view_proj, &transforms[g], c.min, c.max);
        self.clusters.iter().map(|(g, clusters)| clusters.iter().map(|c| rect(*g, c)).collect()).collect()
    }

    /// Queued renders as this frame records them.
    fn writes(&mut self, ops: Vec<PageOp>) -> Vec<TileWrite> {
        let view_proj = self.view_proj();
        let (draws, clusters, rects) = (&mut self.draws, &self.clusters, &self.cluster_rects);
        ops.into_iter()
            .map(|op| {
                let runs = draws.of(clusters, rects, op.key).to_vec();
                tile_write(op, &view_proj, runs)
            })
            .collect()
    }

    /// This frame's tile rendering time: `time_ms`, or `time_share` of the other passes' time
    /// in the frame before where that is less.
    fn time_budget_ms(&self) -> f64 {
        let AsmTimeBudget { time_ms, time_share } = self.settings.time;
        time_ms.min(self.other_ms.map_or(f64::INFINITY, |ms| time_share * ms))
    }

    /// World to the light map's clip space this frame.
    fn view_proj(&self) -> Mat4 {
        Mat4::from_cols_array_2d(&self.record.expect("update sets the record").view_proj)
    }

    /// Marks the tiles the last frame's lighting and this frame's analysis looked up as used
    /// (the analysis sees the new view first), and counts the analysis' edge pixels for the
    /// slots they ask for: each pixel the slot holding it in the tile as many levels below the
    /// tile its texels came from as it lacks (at most `ASM_CHAIN_LEVELS`), with the levels it
    /// lacks.
    fn read_requests(&mut self) -> Result<Vec<Request>> {
        // A record's cells are 16 bits an axis (x | y << 16), fine enough for every level of a
        // chain; its first word holds the node, then 5 bits of levels missing and 5 of levels up.
        const _: () = assert!(
            constants::ASM_EDGE_CELL_BITS == 16
                && constants::ASM_CHAIN_LEVELS + 6 <= constants::ASM_EDGE_CELL_BITS
                && constants::ASM_MAX_LEVEL < 32
                && constants::ASM_EDGE_NODE_BITS + 10 == 32
        );
        let last = (self.frame - 1) as u32;
        for (key, mark) in self.lit_keys.iter().zip(read_words(&self.used)?) {
            if mark == last {
                self.pool.touch(*key, self.frame);
            }
        }
        let words = read_words(&self.requests)?;
        let nodes = self.pool.max_tiles() as usize;
        let mut asked: FxHashMap<TileKey, (Slots, u32, u32)> = FxHashMap::default();
        for (node, &key) in self.table_keys.iter().enumerate() {
            let (word, used) = (words[1 + 2 * node], words[2 + 2 * node]);
            // No pixel of this frame's landed in the tile: nothing to note (most of them).
            if word | used == 0 {
                continue;
            }
            self.pool.touch(key, self.frame);
            self.pool.note_used(key, used as Slots, self.frame);
            self.pool.note_read_above(key, (used >> 16) as Slots, self.frame);
            // Slots on edges its own texels resolve: kept when a trial ends.
            self.pool.note(key, (word >> 16) as Slots, self.frame, None);
            // Slots of pixels whose texels came from two levels up or more: the slots of the
            // tile's parent over them, so that they come from one level up at most.
            let fill = (word & 0xffff) as Slots;
            if let (true, Some(parent)) = (fill != 0, key.parent()) {
                let slots = parent_slots(key, fill);
                let entry = asked.entry(parent).or_default();
                entry.0 |= slots;
                entry.1 += slots.count_ones();
                entry.2 += FILL_BENEFIT * slots.count_ones();
            }
        }
        let count = words[0].min(self.edge_capacity) as usize;
        let node_bits = constants::ASM_EDGE_NODE_BITS;
        for edge in words[1 + 2 * nodes..].chunks_exact(constants::ASM_EDGE_WORDS as usize).take(count) {
            let at = self.table_keys[(edge[0] & ((1 << node_bits) - 1)) as usize];
            let (missing, up) = ((edge[0] >> node_bits) & 31, edge[0] >> (node_bits + 5));
            let from = at.level.saturating_sub(up);
            for depth in 1..=missing.min(constants::ASM_CHAIN_LEVELS) {
                let Some((key, texel)) = at.at_level([edge[1] & 0xffff, edge[1] >> 16], from + depth) else {
                    break;
                };
                let slot = texel[0] / constants::ASM_PAGE_TEXELS
                    + SLOT_SIDE * (texel[1] / constants::ASM_PAGE_TEXELS);
                let entry = asked.entry(key).or_default();
                entry.0 |= 1 << slot;
                entry.1 += 1;
                entry.2 += missing - depth + 1;
            }
        }
        Ok(asked
            .into_iter()
            .map(|(key, (slots, edge_pixels, missing_levels))| {
                let triangles = draw_triangles(self.draws.of(&self.clusters, &self.cluster_rects, key));
                Request { key, slots, edge_pixels, missing_levels, triangles }
            })
            .collect())
    }

    /// Requests for more slots of a tile rendered already wait until the analysis has been over
    /// every pixel (its four phases), gathered, so that the tile renders once for all of them
    /// (asked for one phase at a time, most renders were such extensions); a new tile's do not.
    fn defer_extensions(&mut self, requests: Vec<Request>) -> Vec<Request> {
        let mut ready = Vec::new();
        for r in requests {
            if !self.pool.pages(r.key).is_some_and(|p| p.iter().any(Option::is_some)) {
                ready.push(r);
                continue;
            }
            let empty = Request { slots: 0, edge_pixels: 0, missing_levels: 0, ..r };
            let (gathered, _) = self.deferred.entry(r.key).or_insert((empty, self.frame));
            gathered.slots |= r.slots;
            gathered.edge_pixels += r.edge_pixels;
            gathered.missing_levels += r.missing_levels;
        }
        let (frame, pool) = (self.frame, &self.pool);
        self.deferred.retain(|key, (r, since)| {
            if !pool.contains(*key) {
                return false;
            }
            let due = frame + 1 - *since >= ANALYSIS_PHASES;
            if due {
                ready.push(*r);
            }
            !due
        });
        ready
    }

    /// Rebuilds the page table from the pool and uploads it.
    fn write_table(&mut self) -> Result<()> {
        let table = page_table::build(&self.pool)?;
        table.write(&mut self.table)?;
        self.table_keys = table.keys;
        Ok(())
    }

    /// The push constants of each mesh's draw, in the depth prepass and the lighting pass.
    fn draw_push(&self) -> impl Fn(&GpuMesh, &Mat4) -> LocalDrawPush + '_ {
        // Frame numbers wrap after 2^32 frames; a stale mark then only keeps a tile a frame longer.
        let frame = self.frame as u32;
        move |mesh, model| LocalDrawPush {
            model: model.to_cols_array_2d(),
            albedo: [mesh.albedo[0], mesh.albedo[1], mesh.albedo[2], 0.0],
            params: [1, self.pages.first_id(mesh.group, mesh.mesh), frame, 0],
            bias: DEPTH_BIAS,
        }
    }
}

/// The index runs a render of `key` draws: the clusters (per mesh: its group, its clusters)
/// whose bounds `rects` overlap its square, neighbours merged; (mesh, first index, count).
fn tile_draws(
    clusters: &[(usize, Vec<Cluster>)],
    rects: &[Vec<UvRect>],
    key: TileKey,
) -> Vec<(usize, u32, u32)> {
    let square = UvRect::of_tile(key);
    let mut draws: Vec<(usize, u32, u32)> = Vec::new();
    for (m, ((_, clusters), rects)) in clusters.iter().zip(rects).enumerate() {
        let over = clusters.iter().zip(rects).filter(|(_, r)| r.overlaps(&square)).map(|(c, _)| c);
        draws.extend(runs(over).into_iter().map(|(first, count)| (m, first, count)));
    }
    draws
}

/// Each tile's index runs ([`tile_draws`]) under this frame's cluster bounds, found once: a
/// tile's are needed for its request's cost, its evictions' and its render.
#[derive(Default)]
struct FrameDraws(FxHashMap<TileKey, Vec<(usize, u32, u32)>>);

impl FrameDraws {
    /// Forgets every tile's runs: the clusters' bounds are a new frame's.
    fn clear(&mut self) {
        self.0.clear();
    }

    fn of(
        &mut self,
        clusters: &[(usize, Vec<Cluster>)],
        rects: &[Vec<UvRect>],
        key: TileKey,
    ) -> &[(usize, u32, u32)] {
        self.0.entry(key).or_insert_with(|| tile_draws(clusters, rects, key))
    }
}

/// A queued render as the GPU records it: the tile's cropped projection (of the light's
/// `view_proj`) and the index runs it draws.
fn tile_write(op: PageOp, view_proj: &Mat4, draws: Vec<(usize, u32, u32)>) -> TileWrite {
    TileWrite { key: op.key, view_proj: tile_view_proj(view_proj, op.key), draws, stores: op.stores }
}

/// The benefit of a slot asked for to keep a pixel's texels from coming from more than one level
/// up, as many edge pixels' levels lacking.
const FILL_BENEFIT: u32 = 16;

/// Triangles of index runs.
fn draw_triangles(draws: &[(usize, u32, u32)]) -> u64 {
    draws.iter().map(|d| u64::from(d.2 / 3)).sum()
}

/// The light-uv bounds of the object-space box `min`..`max` under `transform`.
fn box_rect(view_proj: &Mat4, transform: &Mat4, min: Vec3, max: Vec3) -> UvRect {
    let (lo, hi) = box_corners(min, max, transform)
        .iter()
        .fold((Vec3::INFINITY, Vec3::NEG_INFINITY), |(lo, hi), c| (lo.min(*c), hi.max(*c)));
    UvRect::of_box(view_proj, lo, hi)
}

/// Milliseconds since `start`.
fn ms_since(start: Instant) -> f64 {
    start.elapsed().as_secs_f64() * 1e3
}

/// A host-readable buffer's contents as native-endian words.
fn read_words(buffer: &Buffer) -> Result<Vec<u32>> {
    Ok(buffer.read()?.chunks_exact(4).map(|b| u32::from_ne_bytes([b[0], b[1], b[2], b[3]])).collect())
}

impl Technique for Asm {
    fn update(&mut self, state: &FrameState) -> Result<()> {
        let start = Instant::now();
        self.frame += 1;
        // The renderer keeps the scene's light count (Renderer::set_light replaces, never adds),
        // and `new` accepted exactly one.
        self.light = state.lights[0];
        let (centre, radius) = scene_sphere(&self.bounds, state.transforms);
        let record = shadow_light(&self.light, centre, radius, constants::ASM_TILE_TEXELS);
        let view_proj = Mat4::from_cols_array_2d(&record.view_proj);
        let rects = self.group_rects_for(&view_proj, state.transforms);
        let reset = self.record.is_none_or(|r| bytes_of(&r) != bytes_of(&record));
        if reset {
            // The light moved (or the depth range changed): every tile's depths are stale. The
            // new pool queues the root's render.
            self.pool = PagePool::new(self.pages.pages(), self.settings.test.page_bytes())?;
            self.deferred.clear();
        } else {
            let moved: Vec<UvRect> = (0..rects.len())
                .filter(|&g| self.transforms[g] != state.transforms[g])
                .flat_map(|g| [self.group_rects[g], rects[g]])
                .collect();
            let touched = |key: TileKey| moved.iter().any(|r| r.overlaps(&UvRect::of_tile(key)));
            let mut stale: Vec<TileKey> =
                self.pool.resident().map(|(key, _)| key).filter(|&k| touched(k)).collect();
            // Coarse levels first: the root leads.
            stale.sort();
            for key in stale {
                self.pool.refresh(key);
            }
        }
        self.record = Some(record);
        self.transforms = state.transforms.to_vec();
        self.group_rects = rects;
        self.cluster_rects = self.cluster_rects_for(&view_proj, state.transforms);
        self.draws.clear();
        let ops = self.pool.take_ops();
        self.refresh = self.writes(ops);
        if reset {
            // The analysis descends the new pool's table; otherwise last frame's `analysed`
            // wrote the table of the pool as it still is (refreshing tiles moves none).
            self.write_table()?;
        }
        self.records.write(0, bytes_of(&record))?;
        self.update_ms = ms_since(start);
        Ok(())
    }

    fn analysis_passes<'a>(&'a self, inputs: &FrameInputs<'a>) -> Vec<Pass<'a>> {
        let (ctx, scene, targets, uniforms) = (inputs.ctx, inputs.scene, inputs.targets, inputs.uniforms);
        let refresh = Pass::new(REFRESH_PASS, move |cmd| {
            self.pages.record(ctx, cmd, scene, &self.refresh);
        });
        // The eye view the analysis reads is the lighting pass' depth prepass.
        let eye_depth = depth_prepass(inputs, &self.prepass_pipeline, self.draw_push());
        let (width, height) = (targets.depth.width, targets.depth.height);
        let analysis = Pass::new("asm_analysis", move |cmd| {
            self.requests.record_zero(cmd);
            ctx.full_barrier(cmd);
            let push = AsmAnalysisPush {
                size: [width, height, self.pool.max_tiles(), self.edge_capacity],
                phase: [(self.frame % ANALYSIS_PHASES) as u32, 0, 0, 0],
                bias: DEPTH_BIAS,
            };
            let group = constants::ASM_ANALYSIS_GROUP;
            self.analysis.dispatch(
                cmd,
                &[
                    Binding::Uniform(uniforms),
                    Binding::Uniform(&self.records),
                    self.pages.depth_binding(),
                    Binding::Texel(&self.table),
                    Binding::Sampled(&targets.depth, &self.nearest),
                    Binding::Storage(&self.requests),
                ],
                bytes_of(&push),
                [width.div_ceil(2 * group), height.div_ceil(2 * group), 1],
            );
        });
        vec![refresh, eye_depth, analysis]
    }

    fn analysed(&mut self) -> Result<()> {
        let start = Instant::now();
        let mut requests = self.read_requests()?;
        requests.retain(|r| !self.pool.note(r.key, r.slots, self.frame, Some(r.benefit() as f32)));
        let requests = self.defer_extensions(requests);
        let model = self.cost.scaled(self.cost_scale);
        let (frame, time_ms) = (self.frame, self.time_budget_ms());
        self.evicted = 0;
        let (mut ops, mut failed) = (Vec::new(), None);
        // A tile renders once a frame (`PagePool::merged`): a render queued already is paid.
        let mut queued = FxHashSet::default();
        let (draws, clusters, rects) = (&mut self.draws, &self.clusters, &self.cluster_rects);
        let mut cost = |key: TileKey| model.cost_ms(draw_triangles(draws.of(clusters, rects, key)));
        plan(requests, &model, time_ms, |request, left_ms| {
            let own = if queued.contains(&request.key) { 0.0 } else { model.cost_ms(request.triangles) };
            // The evictions' renders are made only in what the budget leaves after this one's.
            let mut extra = 0.0;
            let mut afford = |keys: &[TileKey]| {
                let new: Vec<TileKey> = keys.iter().filter(|k| !queued.contains(*k)).copied().collect();
                let ms: f64 = new.iter().map(|&k| cost(k)).sum();
                let fits = own + extra + ms <= left_ms || ms == 0.0;
                if fits {
                    extra += ms;
                    queued.extend(new);
                }
                fits
            };
            // The pool weighs tiles by benefit alone: an eviction trades pages, which every
            // tile takes alike, where the plan's order trades milliseconds.
            let insert = self.pool.insert_within(
                request.key,
                request.slots,
                frame,
                request.benefit() as f32,
                &mut afford,
            );
            let taken = self.pool.take_ops();
            let ms =
                extra + taken.iter().filter(|op| queued.insert(op.key)).map(|op| cost(op.key)).sum::<f64>();
            ops.extend(taken);
            match insert {
                Ok(Insert::Inserted { evicted }) => {
                    self.evicted += evicted;
                    (ms, true)
                }
                Ok(_) => (ms, false),
                Err(e) => {
                    failed.get_or_insert(e);
                    (ms, false)
                }
            }
        });
        if let Some(e) = failed {
            return Err(e);
        }
        self.pool.end_trials(frame);
        ops.extend(self.pool.take_ops());
        self.render = self.writes(self.pool.merged(ops));
        self.planned_ms = self.render.iter().map(|w| self.cost.cost_ms(draw_triangles(&w.draws))).sum();
        self.write_table()?;
        self.lit_keys.clone_from(&self.table_keys);
        self.stats = AsmStats {
            budget_bytes: self.settings.budget_bytes(),
            bytes_used: self.pool.bytes_in_use() + self.memory.total() - self.memory.pages,
            memory: self.memory,
            resident_tiles: self.table_keys.len(),
            deepest_level: self.table_keys.iter().map(|k| k.level).max().unwrap_or(0),
            refreshed: self.refresh.iter().map(|w| w.key).collect(),
            rendered: self.render.iter().map(|w| w.key).collect(),
            evicted: self.evicted,
            cost: (model.ms_per_triangle, model.ms_per_tile),
            plan_ms: self.update_ms + ms_since(start),
        };
        Ok(())
    }

    fn passes<'a>(&'a self, inputs: &FrameInputs<'a>) -> Vec<Pass<'a>> {
        let (ctx, scene) = (inputs.ctx, inputs.scene);
        let tiles = Pass::new(TILES_PASS, move |cmd| {
            self.pages.record(ctx, cmd, scene, &self.render);
        });
        let mut bindings = vec![
            Binding::Uniform(inputs.uniforms),
            Binding::Uniform(&self.records),
            self.pages.depth_binding(),
            Binding::Texel(&self.table),
            Binding::Storage(&self.used),
        ];
        bindings.extend(self.pages.id_binding());
        let lighting = scene_pass(inputs, &self.scene_pipeline, bindings, self.draw_push());
        vec![tiles, lighting]
    }

    /// Keeps the GPU time of the frame's other passes for the next frame's tile budget, and
    /// scales the cost model by how long this frame's planned tiles took against what the
    /// start-up model predicted (`plan::rescaled`).
    fn timed(&mut self, timings: &[PassTiming]) {
        let others = timings.iter().filter(|t| !TILE_PASSES.contains(&t.name));
        self.other_ms = others.map(|t| t.gpu_ms).sum::<Option<f64>>().filter(|ms| *ms > 0.0);
        // Frames of a few tiles time mostly the pass' own overhead.
        if self.planned_ms < 4.0 * self.cost.ms_per_tile.max(0.01) {
            return;
        }
        let measured = timings.iter().find(|t| t.name == TILES_PASS).and_then(|t| t.gpu_ms);
        if let Some(ms) = measured.filter(|ms| *ms > 0.0) {
            self.cost_scale = rescaled(self.cost_scale, self.planned_ms, ms);
        }
    }

    /// Shadow memory: everything the technique allocated up front (within the budget),
    /// whatever is resident.
    fn stats(&self) -> TechniqueStats {
        TechniqueStats {
            shadow_memory_bytes: Some(self.memory.total()),
            asm: Some(self.stats.clone()),
            ..Default::default()
        }
    }
}
