//! Build-time code generation for everything GLSL and Rust share (see src/layouts.rs):
//!
//! - every top-level `.comp`/`.vert`/`.frag` in `shaders-glsl/` becomes `$OUT_DIR/<name>.spv`,
//!   listed as byte constants in `$OUT_DIR/shaders.rs`;
//! - `shaders-glsl/include/constants.glsl` (`#define KAGE_NAME value`) becomes
//!   `$OUT_DIR/constants.rs`;
//! - the `struct`s of `shaders-glsl/include/layouts.glsl` become `#[repr(C)]` Rust structs with
//!   std430 offsets in `$OUT_DIR/layouts.rs`, with compile-time size and offset assertions.
//!
//! Linking shaderc: `.cargo/config.toml` points `SHADERC_LIB_DIR` at `build/shaderc`, whose
//! `libshaderc_shared.so` is a GNU ld script naming Debian's static shaderc, glslang and
//! SPIRV-Tools archives (vendor-notes.md, "Building shaders"): shaderc-sys links it as a shared
//! library, so it never falls back to building glslang from source.

mod constants;
mod layouts;
mod shaders;

use constants::generate_constants;
use layouts::generate_layouts;
use shaders::compile_shaders;
use std::fs;
use std::path::{Path, PathBuf};

/// The C ABI version (see `kage_abi` in src/capi/mod.rs).
const C_ABI_VERSION: u32 = 1;

fn main() {
    let manifest_dir = PathBuf::from(env("CARGO_MANIFEST_DIR"));
    let out_dir = PathBuf::from(env("OUT_DIR"));
    // Canonical, so that error messages name `/…/shaders-glsl/x.comp` without `engine/..`.
    let shader_dir = fs::canonicalize(manifest_dir.join("../shaders-glsl"))
        .unwrap_or_else(|e| panic!("cannot find shaders-glsl/ next to engine/: {e}"));
    let include_dir = shader_dir.join("include");

    // The C ABI's version in libkage.so's SONAME, so that the dynamic loader refuses to pair a
    // host with a library of another ABI (the same number as `kage_abi::Version` in
    // src/capi/mod.rs; the C host tests check that they agree).
    println!("cargo:rustc-cdylib-link-arg=-Wl,-soname,libkage.so.{C_ABI_VERSION}");

    println!("cargo:rerun-if-changed={}", shader_dir.display());
    println!("cargo:rerun-if-changed={}", include_dir.display());
    let top_level = list_files(&shader_dir);
    for file in top_level.iter().chain(&list_files(&include_dir)) {
        println!("cargo:rerun-if-changed={}", file.display());
    }

    let result = generate_constants(&include_dir.join("constants.glsl"))
        .and_then(|(constants, rust)| {
            write(&out_dir.join("constants.rs"), &rust);
            generate_layouts(&include_dir.join("layouts.glsl"), &constants)
        })
        .map(|rust| write(&out_dir.join("layouts.rs"), &rust))
        .and_then(|()| compile_shaders(&top_level, &include_dir, &out_dir))
        .map(|rust| write(&out_dir.join("shaders.rs"), &rust));
    if let Err(message) = result {
        // A plain message and exit code read better in cargo's output than a panic's backtrace.
        eprintln!("error: {message}");
        std::process::exit(1);
    }
}

fn env(name: &str) -> String {
    std::env::var(name).unwrap_or_else(|_| panic!("cargo did not set {name}"))
}

fn write(path: &Path, text: impl AsRef<[u8]>) {
    fs::write(path, text).unwrap_or_else(|e| panic!("cannot write {}: {e}", path.display()));
}

/// Plain files directly in `dir`, sorted so that generated code is deterministic.
fn list_files(dir: &Path) -> Vec<PathBuf> {
    let Ok(entries) = fs::read_dir(dir) else {
        return Vec::new();
    };
    let mut files: Vec<PathBuf> = entries
        .map(|e| e.unwrap_or_else(|e| panic!("cannot list {}: {e}", dir.display())).path())
        .filter(|p| p.is_file())
        .collect();
    files.sort();
    files
}

pub fn read(path: &Path) -> Result<String, String> {
    fs::read_to_string(path).map_err(|e| format!("cannot read {}: {e}", path.display()))
}
