//! Wavefront OBJ in and out. Reading goes through tobj with one index per vertex; all objects
//! and groups in a file become one mesh, since a scene gives one albedo per OBJ.
use std::fmt::Write as _;
use std::io::Cursor;
use std::path::Path;

use super::{Mesh, SceneError};
use crate::files;

/// Parses OBJ text held in memory. Errors name no file; the caller attributes them.
pub fn parse_obj(bytes: &[u8], name: &str, albedo: [f32; 3]) -> Result<Mesh, SceneError> {
    // Materials are not part of a Kage scene; `mtllib` lines are accepted and ignored.
    let ignore_materials = |_: &Path| Ok(Default::default());
    let (models, _) = tobj::load_obj_buf(&mut Cursor::new(bytes), &tobj::GPU_LOAD_OPTIONS, ignore_materials)
        .map_err(|e| SceneError::invalid(format!("malformed OBJ: {e}")))?;

    let mut positions = Vec::new();
    let mut normals = Vec::new();
    let mut indices = Vec::new();
    // File normals are only used when every object has them; otherwise all are computed.
    let mut every_vertex_has_a_normal = true;
    for model in models {
        let mesh = model.mesh;
        let base =
            u32::try_from(positions.len()).map_err(|_| SceneError::invalid("OBJ has too many vertices"))?;
        every_vertex_has_a_normal &= mesh.normals.len() == mesh.positions.len();
        positions.extend(mesh.positions.chunks_exact(3).map(|p| [p[0], p[1], p[2]]));
        normals.extend(mesh.normals.chunks_exact(3).map(|n| [n[0], n[1], n[2]]));
        indices.extend(mesh.indices.iter().map(|i| base + i));
    }
    let normals = every_vertex_has_a_normal.then_some(normals);
    Mesh::new(name, positions, normals, indices, albedo)
}

/// Reads an OBJ file (a regular file within [`files::OBJ`]); every error names `path`.
pub fn load_obj(path: &Path, albedo: [f32; 3]) -> Result<Mesh, SceneError> {
    let bytes = files::read(path, files::OBJ).map_err(|e| SceneError::in_file(path, e.to_string()))?;
    let name = path.file_stem().map(|s| s.to_string_lossy().into_owned()).unwrap_or_default();
    parse_obj(&bytes, &name, albedo).map_err(|e| SceneError::in_file(path, e.problem()))
}

/// Writes positions, normals and triangles (`f a//a b//b c//c`). Floats are written in Rust's
/// shortest round-trip form, so reading the file back gives the same bits; the albedo lives in
/// the scene file, not here.
pub fn write_obj(mesh: &Mesh, path: &Path) -> Result<(), SceneError> {
    let mut text = format!("# {} (written by Kage)\n", mesh.name);
    for [x, y, z] in &mesh.positions {
        let _ = writeln!(text, "v {x} {y} {z}");
    }
    for [x, y, z] in &mesh.normals {
        let _ = writeln!(text, "vn {x} {y} {z}");
    }
    for tri in mesh.indices.chunks_exact(3) {
        let [a, b, c] = [tri[0] + 1, tri[1] + 1, tri[2] + 1];
        let _ = writeln!(text, "f {a}//{a} {b}//{b} {c}//{c}");
    }
    std::fs::write(path, text).map_err(|e| SceneError::in_file(path, format!("cannot write: {e}")))
}
