//! Wavefront OBJ in and out. Reading goes through tobj with one index per vertex; all objects
//! and groups in a file become one mesh, since a scene gives one albedo per OBJ, except where
//! their materials' `map_Kd` differ: a file read from disk ([`load_obj`]) gives one mesh per
//! albedo map its faces use (texture coordinates turned from OBJ's v-up to glTF's v-down).
use std::collections::HashMap;
use std::fmt::Write as _;
use std::io::Cursor;
use std::path::Path;
use std::sync::Arc;

use super::albedo_map::{AlbedoMap, Texturing};
use super::{Mesh, SceneError};
use crate::files;

/// Parses OBJ text held in memory as one mesh; materials (and their maps) are ignored. Errors
/// name no file; the caller attributes them.
pub fn parse_obj(bytes: &[u8], name: &str, albedo: [f32; 3]) -> Result<Mesh, SceneError> {
    let models = models(bytes, |_| Ok(Default::default()))?.0;
    let mut meshes = meshes(models, name, albedo, &mut |_| Ok(None))?;
    Ok(meshes.remove(0))
}

/// Reads an OBJ file (a regular file within [`files::OBJ`]) and the albedo maps (`map_Kd`) of
/// the materials its faces use, from the material library beside it: one mesh per map (one
/// mesh, named after the file, where its faces use one map or none). A library that cannot be
/// read leaves the meshes without maps, with a note. Every error names the file at fault.
pub fn load_obj(path: &Path, albedo: [f32; 3]) -> Result<Vec<Mesh>, SceneError> {
    let bytes = files::read(path, files::OBJ).map_err(|e| SceneError::in_file(path, e.to_string()))?;
    let name = path.file_stem().map(|s| s.to_string_lossy().into_owned()).unwrap_or_default();
    let folder = path.parent().unwrap_or(Path::new(""));
    let library = |mtl: &Path| {
        let bytes =
            files::read(&folder.join(mtl), files::OBJ).map_err(|_| tobj::LoadError::OpenFileFailed)?;
        tobj::load_mtl_buf(&mut Cursor::new(bytes))
    };
    let (models, materials) = models(&bytes, library).map_err(|e| SceneError::in_file(path, e.problem()))?;
    let materials = materials.unwrap_or_else(|e| {
        eprintln!(
            "kage: note: {}: its material library cannot be read ({e}): no albedo maps",
            path.display()
        );
        Vec::new()
    });
    let mut read: HashMap<String, Arc<AlbedoMap>> = HashMap::new();
    let mut map_of = |material: Option<usize>| -> Result<Option<Arc<AlbedoMap>>, SceneError> {
        let Some(file) = material.and_then(|m| materials.get(m)).and_then(|m| m.diffuse_texture.clone())
        else {
            return Ok(None);
        };
        if !read.contains_key(&file) {
            read.insert(file.clone(), Arc::new(AlbedoMap::read(&folder.join(&file))?));
        }
        Ok(read.get(&file).cloned())
    };
    meshes(models, &name, albedo, &mut map_of).map_err(|e| e.attributed_to(path))
}

/// An OBJ file's models and, where its library could be read, its materials.
type ObjContents = (Vec<tobj::Model>, Result<Vec<tobj::Material>, tobj::LoadError>);

fn models(bytes: &[u8], library: impl Fn(&Path) -> tobj::MTLLoadResult) -> Result<ObjContents, SceneError> {
    tobj::load_obj_buf(&mut Cursor::new(bytes), &tobj::GPU_LOAD_OPTIONS, library)
        .map_err(|e| SceneError::invalid(format!("malformed OBJ: {e}")))
}

/// The models' triangles as one mesh per albedo map (`map_of` a model's material), in the order
/// the maps first appear.
fn meshes(
    models: Vec<tobj::Model>,
    name: &str,
    albedo: [f32; 3],
    map_of: &mut dyn FnMut(Option<usize>) -> Result<Option<Arc<AlbedoMap>>, SceneError>,
) -> Result<Vec<Mesh>, SceneError> {
    // Per map: positions, normals, texture coordinates, indices; whether every vertex has a
    // normal and a texture coordinate.
    struct Part {
        map: Option<Arc<AlbedoMap>>,
        positions: Vec<[f32; 3]>,
        normals: Vec<[f32; 3]>,
        uvs: Vec<[f32; 2]>,
        indices: Vec<u32>,
        all_normals: bool,
        all_uvs: bool,
    }
    let mut parts: Vec<Part> = Vec::new();
    for model in models {
        let map = map_of(model.mesh.material_id)?;
        let at =
            match parts.iter().position(|p| p.map.as_ref().map(Arc::as_ptr) == map.as_ref().map(Arc::as_ptr))
            {
                Some(at) => at,
                None => {
                    let part = Part {
                        map,
                        positions: Vec::new(),
                        normals: Vec::new(),
                        uvs: Vec::new(),
                        indices: Vec::new(),
                        all_normals: true,
                        all_uvs: true,
                    };
                    parts.push(part);
                    parts.len() - 1
                }
            };
        let (part, mesh) = (&mut parts[at], model.mesh);
        let base = u32::try_from(part.positions.len())
            .map_err(|_| SceneError::invalid("OBJ has too many vertices"))?;
        let count = mesh.positions.len() / 3;
        part.all_normals &= mesh.normals.len() == 3 * count;
        part.all_uvs &= mesh.texcoords.len() == 2 * count;
        part.positions.extend(mesh.positions.chunks_exact(3).map(|p| [p[0], p[1], p[2]]));
        part.normals.extend(mesh.normals.chunks_exact(3).map(|n| [n[0], n[1], n[2]]));
        part.uvs.extend(mesh.texcoords.chunks_exact(2).map(|t| [t[0], 1.0 - t[1]]));
        part.indices.extend(mesh.indices.iter().map(|i| base + i));
    }
    if parts.is_empty() {
        // No models at all: the mesh's own check names the problem (no triangles).
        return Ok(vec![Mesh::new(name, Vec::new(), None, Vec::new(), albedo)?]);
    }
    let several = parts.len() > 1;
    parts
        .into_iter()
        .enumerate()
        .map(|(k, part)| {
            // File normals are only used when every vertex of the part has one.
            let normals = part.all_normals.then_some(part.normals);
            let name = if several { format!("{name}.{k}") } else { name.to_owned() };
            match part.map {
                Some(map) if part.all_uvs => {
                    let texturing = Texturing { map, uvs: part.uvs };
                    Mesh::new_textured(name, part.positions, normals, part.indices, albedo, texturing)
                }
                Some(map) => Err(SceneError::invalid(format!(
                    "mesh \"{name}\" uses albedo map {} but not every vertex has a texture coordinate (vt)",
                    map.name
                ))),
                None => Mesh::new(name, part.positions, normals, part.indices, albedo),
            }
        })
        .collect()
}

/// Writes positions, normals and triangles (`f a//a b//b c//c`). Floats are written in Rust's
/// shortest round-trip form, so reading the file back gives the same bits; the albedo lives in
/// the scene file, not here. A mesh with an albedo map also gets texture coordinates (`vt`, v
/// turned to OBJ's v-up: they read back to within f32 rounding of 1 − v) and, beside the file
/// under its name, a material library whose `map_Kd` is the map as PNG. OBJ has no sampler: a
/// map that does not repeat and filter smoothly reads back as one that does (with a note).
pub fn write_obj(mesh: &Mesh, path: &Path) -> Result<(), SceneError> {
    let write = |path: &Path, bytes: &[u8]| {
        std::fs::write(path, bytes).map_err(|e| SceneError::in_file(path, format!("cannot write: {e}")))
    };
    let mut text = format!("# {} (written by Kage)\n", mesh.name);
    if let Some(texturing) = &mesh.texturing {
        let (mtl, png) = (path.with_extension("mtl"), path.with_extension("png"));
        let file_name = |p: &Path| p.file_name().unwrap_or_default().to_string_lossy().into_owned();
        let _ = writeln!(text, "mtllib {}\nusemtl albedo_map", file_name(&mtl));
        write(&mtl, format!("newmtl albedo_map\nmap_Kd {}\n", file_name(&png)).as_bytes())?;
        write(&png, &texturing.map.png())?;
        let map = &texturing.map;
        if map.wrap != [super::albedo_map::Wrap::Repeat; 2] || map.filter != super::albedo_map::Filter::SMOOTH
        {
            eprintln!(
                "kage: note: {}: OBJ has no sampler; albedo map {} reads back repeating, with linear filtering and mipmaps",
                path.display(),
                map.name
            );
        }
    }
    for [x, y, z] in &mesh.positions {
        let _ = writeln!(text, "v {x} {y} {z}");
    }
    for [x, y, z] in &mesh.normals {
        let _ = writeln!(text, "vn {x} {y} {z}");
    }
    for [u, v] in mesh.texturing.iter().flat_map(|t| &t.uvs) {
        let _ = writeln!(text, "vt {u} {}", 1.0 - v);
    }
    let textured = mesh.texturing.is_some();
    for tri in mesh.indices.chunks_exact(3) {
        let [a, b, c] = [tri[0] + 1, tri[1] + 1, tri[2] + 1];
        let _ = if textured {
            writeln!(text, "f {a}/{a}/{a} {b}/{b}/{b} {c}/{c}/{c}")
        } else {
            writeln!(text, "f {a}//{a} {b}//{b} {c}//{c}")
        };
    }
    write(path, text.as_bytes())
}
