//! A bounded mutation fuzzer over the readers of what users hand Kage: scene JSON, glTF (JSON and
//! GLB), OBJ, EXR
//! and HDR maps, probe position files, and probe positions (tetrahedralized). Each starts from its committed seed
//! (tests/fuzz/seeds/), which must read cleanly, and reads `KAGE_FUZZ_ITERATIONS` (default 2,000)
//! mutants of it: bytes flipped, inserted, deleted, repeated, and numbers replaced by extreme
//! ones. Every read must return, Ok or a clear error: a panic or an abort fails the test. The
//! mutants are deterministic (a fixed seed per reader), so a failure reproduces; run longer with
//! `KAGE_FUZZ_ITERATIONS=100000 cargo test --release -p kage-tests --test fuzz_readers`.
use glam::DVec3;
use kage::scene::{parse_obj, EnvMap, Scene};
use kage::sh::ShRgb9;
use kage::techniques::probes::{positions_file, ProbeSet};
use std::panic::{catch_unwind, AssertUnwindSafe};
use std::path::{Path, PathBuf};

fn seed(name: &str) -> Vec<u8> {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("fuzz/seeds").join(name);
    std::fs::read(&path).unwrap_or_else(|e| panic!("{}: {e}", path.display()))
}

fn iterations() -> usize {
    std::env::var("KAGE_FUZZ_ITERATIONS").ok().and_then(|v| v.parse().ok()).unwrap_or(2000)
}

/// xorshift64*: the mutants of a run are the same on every machine.
struct Rng(u64);

impl Rng {
    fn next(&mut self) -> u64 {
        self.0 ^= self.0 >> 12;
        self.0 ^= self.0 << 25;
        self.0 ^= self.0 >> 27;
        self.0.wrapping_mul(0x2545_f491_4f6c_dd1d)
    }

    fn below(&mut self, n: usize) -> usize {
        (self.next() % n.max(1) as u64) as usize
    }
}

/// Numbers that break naive readers: huge, tiny, negative, not numbers, counts at type limits.
const EXTREMES: &[&str] =
    &["1e38", "-1e38", "1e-45", "0", "-0", "nan", "inf", "4294967295", "18446744073709551616", "-1", "1e400"];

/// One mutant of `input`: one to four edits.
fn mutate(input: &[u8], rng: &mut Rng) -> Vec<u8> {
    let mut out = input.to_vec();
    for _ in 0..1 + rng.below(4) {
        let at = rng.below(out.len() + 1);
        match rng.below(6) {
            0 if !out.is_empty() => {
                let i = at.min(out.len() - 1);
                out[i] ^= 1 << rng.below(8);
            }
            1 => out.insert(at, rng.next() as u8),
            2 if at < out.len() => {
                let end = (at + 1 + rng.below(16)).min(out.len());
                out.drain(at..end);
            }
            3 if at < out.len() => {
                let end = (at + 1 + rng.below(32)).min(out.len());
                let piece = out[at..end].to_vec();
                out.splice(at..at, piece);
            }
            4 => {
                // Replace the number starting at or after `at` by an extreme one.
                let start = (at..out.len()).find(|&i| out[i].is_ascii_digit()).unwrap_or(out.len());
                let end = (start..out.len())
                    .find(|&i| !(out[i].is_ascii_digit() || out[i] == b'.' || out[i] == b'e'))
                    .unwrap_or(out.len());
                let extreme = EXTREMES[rng.below(EXTREMES.len())].as_bytes().to_vec();
                out.splice(start..end, extreme);
            }
            _ => {
                let i = rng.below(out.len().max(1));
                out.truncate(i.max(1));
            }
        }
    }
    out
}

/// Reads `iterations()` mutants of `seed` with `read`; any panic fails, naming the mutant.
fn fuzz(name: &str, seed: &[u8], stream: u64, mut read: impl FnMut(&[u8])) {
    let mut rng = Rng(0x9e37_79b9_7f4a_7c15 ^ stream);
    for i in 0..iterations() {
        let mutant = mutate(seed, &mut rng);
        if catch_unwind(AssertUnwindSafe(|| read(&mutant))).is_err() {
            let dump = std::env::temp_dir().join(format!("kage-fuzz-{name}-{i}"));
            let _ = std::fs::write(&dump, &mutant);
            panic!("{name}: mutant {i} panicked (written to {})", dump.display());
        }
    }
}

fn scratch() -> PathBuf {
    kage_tests::scratch_dir("fuzz")
}

#[test]
fn scene_files() {
    let seed = seed("scene.json");
    let path = scratch().join("scene.json");
    std::fs::write(&path, &seed).unwrap();
    Scene::load(&path).expect("the seed scene loads");
    fuzz("scene.json", &seed, 1, |bytes| {
        std::fs::write(&path, bytes).unwrap();
        if let Ok(scene) = Scene::load(&path) {
            // What loads must also pass the renderer's own checks, or be refused by them.
            let _ = scene.validate();
        }
    });
}

#[test]
fn obj_meshes() {
    let seed = seed("mesh.obj");
    parse_obj(&seed, "seed", [0.5; 3]).expect("the seed mesh parses");
    fuzz("mesh.obj", &seed, 2, |bytes| {
        let _ = parse_obj(bytes, "mutant", [0.5; 3]);
    });
}

#[test]
fn exr_and_hdr_maps() {
    type Reader = fn(&[u8]) -> Result<EnvMap, kage::scene::SceneError>;
    let readers: [(&str, u64, Reader); 2] =
        [("map.exr", 3, EnvMap::from_exr_bytes), ("map.hdr", 4, EnvMap::from_hdr_bytes)];
    for (name, stream, read) in readers {
        let seed = seed(name);
        read(&seed).expect("the seed map reads");
        fuzz(name, &seed, stream, |bytes| {
            let _ = read(bytes);
        });
    }
}

/// The same EXR mutants through `kage compare`'s reader (`imageio::read_exr`, from a file),
/// which checks the header against its own limits and decodes all four channels.
#[test]
fn exr_images() {
    let seed = seed("map.exr");
    let path = kage_tests::scratch_dir("fuzz-read-exr").join("image.exr");
    std::fs::write(&path, &seed).unwrap();
    kage::imageio::read_exr(&path).expect("the seed image reads");
    fuzz("image.exr", &seed, 6, |bytes| {
        std::fs::write(&path, bytes).unwrap();
        let _ = kage::imageio::read_exr(&path);
    });
}

/// Probe positions as little-endian f64 triples (a mutant may hold NaN, infinities, duplicates,
/// coplanar or nearly coincident points), tetrahedralized with constant SH.
#[test]
fn probe_sets() {
    let positions = |bytes: &[u8]| -> Vec<DVec3> {
        bytes
            .chunks_exact(24)
            .take(256)
            .map(|c| {
                let f = |i: usize| f64::from_le_bytes(c[8 * i..8 * i + 8].try_into().unwrap());
                DVec3::new(f(0), f(1), f(2))
            })
            .collect()
    };
    let seed = seed("probes.bin");
    let points = positions(&seed);
    ProbeSet::tetrahedral(&points, vec![ShRgb9::default(); points.len()]).expect("the seed set builds");
    fuzz("probes.bin", &seed, 5, |bytes| {
        let points = positions(bytes);
        let _ = ProbeSet::tetrahedral(&points, vec![ShRgb9::default(); points.len()]);
    });
}

/// Probe position files as `kage probes place` writes them and `probes tetrahedralize`,
/// `probes lookup` and `render --probe-positions` read them, each set read tetrahedralized.
#[test]
fn probe_files() {
    let seed = seed("probes.json");
    let points = positions_file::parse(&seed).expect("the seed file reads");
    ProbeSet::tetrahedral(&points, vec![ShRgb9::default(); points.len()]).expect("the seed set builds");
    fuzz("probes.json", &seed, 6, |bytes| {
        if let Ok(points) = positions_file::parse(bytes) {
            let _ = ProbeSet::tetrahedral(&points, vec![ShRgb9::default(); points.len()]);
        }
    });
}

/// glTF as JSON (a .gltf with the buffers and images it names beside it) and as GLB (one binary
/// file: its chunk headers, JSON and embedded buffer and images): textures and samplers, node
/// animation, cameras, and a Blender export with a spot light. Each seed is copied with its
/// folder's files into a scratch folder, where its mutants are read.
#[test]
fn gltf_files() {
    let assets = Path::new(env!("CARGO_MANIFEST_DIR")).join("assets/gltf");
    let seeds = [
        "two-groups.gltf",
        "khronos-box-textured/BoxTextured.gltf",
        "khronos-box-animated/BoxAnimated.gltf",
        "blender-suzanne/scene.glb",
    ];
    for (stream, name) in (8..).zip(seeds) {
        let source = assets.join(name);
        let dir = scratch();
        for entry in std::fs::read_dir(source.parent().unwrap()).unwrap() {
            let entry = entry.unwrap().path();
            if entry.is_file() {
                std::fs::copy(&entry, dir.join(entry.file_name().unwrap())).unwrap();
            }
        }
        let path = dir.join(source.file_name().unwrap());
        Scene::load(&path).unwrap_or_else(|e| panic!("the seed {name} loads: {e}"));
        let seed = std::fs::read(&path).unwrap();
        fuzz(name, &seed, stream, |bytes| {
            std::fs::write(&path, bytes).unwrap();
            let _ = Scene::load(&path);
        });
    }
}
