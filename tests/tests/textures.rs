//! Albedo maps (glTF baseColorTexture, OBJ map_Kd): read with their sampler and coordinates,
//! shaded per pixel by every technique and by the reference, on the Khronos sample BoxTextured
//! (tests/assets/gltf/khronos-box-textured).
use glam::{Mat4, Vec3, Vec4};
use kage::reference::render::{LightMode, ReferenceOptions, ReferenceRenderer};
use kage::renderer::{RenderOptions, Renderer};
use kage::scene::albedo_map::{srgb_to_linear, Filter, Wrap};
use kage::scene::{shapes, Camera, EnvMap, Group, Light, Scene, Transform};
use kage_tests::{every_technique, scratch_dir, Validated};
use std::path::PathBuf;

fn box_textured() -> Scene {
    let path =
        PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("assets/gltf/khronos-box-textured/BoxTextured.gltf");
    Scene::load(&path).unwrap()
}

/// The map, its sampler (repeat, linear magnification, nearest minification between linear
/// mipmaps: minFilter 9986) and TEXCOORD_0 (0 to 6 along the six faces) as the file gives them.
#[test]
fn box_textured_reads_its_map_sampler_and_coordinates() {
    let scene = box_textured();
    let mesh = &scene.groups[0].meshes[0];
    let texturing = mesh.texturing.as_ref().expect("the box has an albedo map");
    let map = &texturing.map;
    assert_eq!((map.width, map.height, map.texels.len()), (256, 256, 65536));
    assert_eq!(map.wrap, [Wrap::Repeat; 2]);
    assert_eq!(map.filter, Filter { magnify_linear: true, minify_linear: false, mipmaps: Some(true) });
    assert_eq!(texturing.uvs.len(), mesh.positions.len());
    let most = texturing.uvs.iter().fold([f32::MIN; 2], |m, uv| [m[0].max(uv[0]), m[1].max(uv[1])]);
    assert!((most[0] - 6.0).abs() < 1e-6 && (most[1] - 1.0).abs() < 1e-6, "{most:?}");
    // The logo on white: the top-left texel is the light grey border; the logo's sky is blue
    // at the top, its ground green at the bottom (rows run down, as glTF's v does).
    assert!(map.texels[0][..3].iter().all(|&c| c > 200), "{:?}", map.texels[0]);
    let [sky, ground] = [64, 200].map(|row| map.texels[row * 256 + 128]);
    assert!(sky[2] > sky[0] + 40 && ground[1] > ground[2] + 40, "{sky:?} {ground:?}");
}

/// The box on an untextured floor under a spot light and the constant sky: something for every
/// technique (a light for shadowmap and ASM, a static group for the probes, the box the moving
/// one), seen from `camera`.
fn box_on_floor(textured: bool) -> Scene {
    let mut scene = box_textured();
    if !textured {
        scene.groups[0].meshes[0].texturing = None;
    }
    let floor = shapes::plane("floor", [4.0, 4.0], [9, 9], [0.6; 3]).unwrap();
    let at = Transform { translation: Vec3::new(0.0, -0.5, 0.0), ..Transform::default() };
    scene.groups.push(Group::new("floor", vec![floor], at));
    scene.lights.push(Light::Spot {
        position: Vec3::new(1.0, 3.0, 2.5),
        direction: Vec3::new(-1.0, -3.0, -2.5).normalize(),
        fov_deg: 60.0,
        intensity: [8.0; 3],
    });
    scene.camera = Camera::from_arrays([1.2, 1.0, 2.2], [0.0, 0.0, 0.0], [0.0, 1.0, 0.0], 40.0).unwrap();
    scene
}

/// Every technique multiplies its radiance, which is linear in the albedo, by the map's texel:
/// the picture with the map over the same picture without it is, pixel by pixel, the texel the
/// rasterizer samples, the same in every technique. The unshadowed technique's ratio is the
/// yardstick; the others must agree with it to f32 rounding of two products and a quotient
/// (1e-5 relative), on the box's pixels, which must show the texture (ratios from the map's
/// dark green to white) while the floor's stay 1.
#[test]
fn every_technique_shades_with_the_albedo_map() {
    let ctx = Validated::new();
    let (textured, plain) = (box_on_floor(true), box_on_floor(false));
    let size = 48;
    let render = |scene: &Scene, options: &RenderOptions| {
        let options = RenderOptions { width: size, height: size, ..options.clone() };
        let mut renderer = Renderer::new(&ctx, scene, &options).unwrap();
        renderer.render().unwrap();
        renderer.image().unwrap().pixels
    };
    let mut yardstick: Option<Vec<Option<[f32; 3]>>> = None;
    for ((kind, with_map), (_, without)) in
        every_technique(&ctx, &textured).into_iter().zip(every_technique(&ctx, &plain))
    {
        let (a, b) = (render(&textured, &with_map), render(&plain, &without));
        // Where the untextured picture has light enough for a quotient to mean something.
        let ratios: Vec<Option<[f32; 3]>> = a
            .iter()
            .zip(&b)
            .map(|(a, b)| (b[..3].iter().all(|&c| c > 1e-3)).then(|| [0, 1, 2].map(|k| a[k] / b[k])))
            .collect();
        let textured_pixels = ratios.iter().flatten().filter(|r| r.iter().any(|&c| c < 0.9)).count();
        assert!(textured_pixels > 100, "{kind:?}: only {textured_pixels} pixels show the map");
        let darkest = ratios.iter().flatten().flat_map(|r| *r).fold(f32::MAX, f32::min);
        assert!(darkest < 0.2, "{kind:?}: the map's dark green is missing (darkest ratio {darkest})");
        match &yardstick {
            None => yardstick = Some(ratios),
            Some(expected) => {
                for (p, (r, e)) in ratios.iter().zip(expected).enumerate() {
                    if let (Some(r), Some(e)) = (r, e) {
                        let off = (0..3).map(|k| (r[k] - e[k]).abs() / e[k].max(1e-3)).fold(0.0, f32::max);
                        assert!(off < 1e-5, "{kind:?}: pixel {p} ratio {r:?}, unshadowed's {e:?}");
                    }
                }
            }
        }
    }
}

/// The texture against the reference, where both are exact but for how they filter: a close-up
/// of the box's front face under the constant sky of radiance 1, whose irradiance π makes the
/// radiance the albedo exactly (L = a/π · π), in the unshadowed technique and in the reference.
/// At 2 pixels per texel the rasterizer reads level 0 bilinearly at the pixel centre c; the
/// reference averages the same bilinear function B over the pixel. B is Lipschitz with constant
/// G = Δ/m per pixel (Δ the largest difference between adjacent texels it interpolates, m = 2
/// pixels per texel), and the mean of |x − c|₁ over a pixel is ½, so |mean − B(c)| ≤ Δ/(2m);
/// the sampler's 8-bit interpolation weights add Δ/256. With the reference's noise (5 standard
/// errors) every pixel must lie within that bound; where the map is flat the bound is the noise
/// alone, so a missing map, turned coordinates or a wrong sRGB decoding fail.
#[test]
fn the_texture_matches_the_reference_texel_for_texel() {
    let ctx = Validated::new();
    let mut scene = box_textured();
    scene.environment = EnvMap::constant([1.0; 3]);
    let (size, m) = (64u32, 2.0f32);
    // The front face (world z = 0.5, the file's −Y face under its root matrix) spans one unit
    // and 256 texels: 64 pixels at 2 per texel cover 0.125 units, from 0.5 units away.
    let half = 0.5 * size as f32 / (256.0 * m);
    let fov = 2.0 * (half / 0.5f32).atan().to_degrees();
    let camera = Camera::from_arrays([0.1, 0.05, 1.0], [0.1, 0.05, 0.0], [0.0, 1.0, 0.0], fov).unwrap();
    scene.camera = camera;

    let options = RenderOptions { width: size, height: size, ..RenderOptions::default() };
    let mut renderer = Renderer::new(&ctx, &scene, &options).unwrap();
    renderer.render().unwrap();
    let raster = renderer.image().unwrap().pixels;
    let light = LightMode::Environment;
    let mut reference =
        ReferenceRenderer::new(&ctx, &scene, &ReferenceOptions { width: size, height: size, light, seed: 7 })
            .unwrap();
    reference.run_batch(256).unwrap();
    let stats = reference.statistics().unwrap();
    let errors = stats.standard_error.as_ref().unwrap();

    let mesh = &scene.groups[0].meshes[0];
    let texturing = mesh.texturing.as_ref().unwrap();
    let map = &texturing.map;
    let linear = |x: i64, y: i64| {
        let wrap = |i: i64, n: u32| i.rem_euclid(i64::from(n)) as usize;
        let t = map.texels[wrap(y, map.height) * map.width as usize + wrap(x, map.width)];
        [0, 1, 2].map(|k| srgb_to_linear(t[k]))
    };
    let model = scene.groups[0].transform.matrix();
    let inverse = (camera.projection(1.0) * camera.view()).inverse();
    let (mut worst, mut flat_pixels) = (0.0f32, 0);
    for j in 0..size {
        for i in 0..size {
            let ndc = |z: f32| {
                let x = 2.0 * (i as f32 + 0.5) / size as f32 - 1.0;
                let y = 2.0 * (j as f32 + 0.5) / size as f32 - 1.0;
                let p = inverse * Vec4::new(x, y, z, 1.0);
                p.truncate() / p.w
            };
            let (origin, direction) = (camera.position, (ndc(1.0) - ndc(0.0)).normalize());
            let uv = hit_uv(mesh, texturing, model, origin, direction).expect("every pixel sees the face");
            // The texels the pixel's bilinear footprint reads (±¼ texel around its centre, and
            // their neighbours): the largest difference between adjacent ones.
            let f = [uv[0] * map.width as f32 - 0.5, uv[1] * map.height as f32 - 0.5];
            let (x0, y0) = ((f[0] - 0.25).floor() as i64, (f[1] - 0.25).floor() as i64);
            let mut delta = 0.0f32;
            for y in y0..=y0 + 2 {
                for x in x0..=x0 + 2 {
                    for (dx, dy) in [(1, 0), (0, 1)] {
                        let (a, b) = (linear(x, y), linear(x + dx, y + dy));
                        delta = delta.max((0..3).map(|k| (a[k] - b[k]).abs()).fold(0.0, f32::max));
                    }
                }
            }
            flat_pixels += usize::from(delta < 0.01);
            let p = (j * size + i) as usize;
            for k in 0..3 {
                let bound = delta / (2.0 * m) + delta / 256.0 + 5.0 * errors[p][k] + 1e-4;
                let off = (raster[p][k] - stats.mean[p][k]).abs();
                worst = worst.max(off / bound);
                assert!(
                    off <= bound,
                    "pixel ({i}, {j}) channel {k}: raster {} reference {} ± {}, bound {bound} (Δ {delta})",
                    raster[p][k],
                    stats.mean[p][k],
                    errors[p][k]
                );
            }
        }
    }
    println!("worst |raster − reference| / bound {worst:.3}; {flat_pixels} pixels where the map is flat");
    assert!(flat_pixels > 200, "the close-up must hold flat regions where only noise is allowed");
}

/// The texture coordinate where the ray from `origin` along `direction` first meets the mesh
/// (placed by `model`), interpolated with the hit's barycentrics.
fn hit_uv(
    mesh: &kage::scene::Mesh,
    texturing: &kage::scene::Texturing,
    model: Mat4,
    origin: Vec3,
    direction: Vec3,
) -> Option<[f32; 2]> {
    let mut best: Option<(f32, [f32; 2])> = None;
    for tri in mesh.indices.chunks_exact(3) {
        let [a, b, c] =
            [0, 1, 2].map(|k| model.transform_point3(Vec3::from(mesh.positions[tri[k] as usize])));
        let (e1, e2) = (b - a, c - a);
        let p = direction.cross(e2);
        let det = e1.dot(p);
        if det.abs() < 1e-12 {
            continue;
        }
        let s = origin - a;
        let u = s.dot(p) / det;
        let q = s.cross(e1);
        let v = direction.dot(q) / det;
        let t = e2.dot(q) / det;
        if u < 0.0 || v < 0.0 || u + v > 1.0 || t <= 0.0 || best.is_some_and(|(near, _)| near <= t) {
            continue;
        }
        let [ta, tb, tc] = [0, 1, 2].map(|k| texturing.uvs[tri[k] as usize]);
        let w = 1.0 - u - v;
        best = Some((t, [0, 1].map(|k| w * ta[k] + u * tb[k] + v * tc[k])));
    }
    best.map(|(_, uv)| uv)
}

/// An OBJ whose material library gives `map_Kd`: its `vt` (v up) read as glTF's (v down), the
/// PNG beside it read as the map; faces of two materials with two maps make two meshes; a
/// library that is missing leaves the mesh plain with a note; a map that is missing is an error
/// naming it.
#[test]
fn obj_map_kd_is_the_albedo_map() {
    let dir = scratch_dir("obj-map-kd");
    let png = |name: &str, rgb: [u8; 3]| {
        let pixels: Vec<u8> = [rgb, [255, 255, 255]].concat().repeat(2);
        image::save_buffer(dir.join(name), &pixels, 2, 2, image::ExtendedColorType::Rgb8).unwrap();
    };
    png("red.png", [255, 0, 0]);
    png("blue.png", [0, 0, 255]);
    std::fs::write(dir.join("two.mtl"), "newmtl a\nmap_Kd red.png\nnewmtl b\nmap_Kd blue.png\n").unwrap();
    let quad = "v 0 0 0\nv 1 0 0\nv 1 0 -1\nv 0 0 -1\nvt 0 0\nvt 1 0\nvt 1 1\nvt 0 1\n";
    let obj = format!("mtllib two.mtl\n{quad}usemtl a\nf 1/1 2/2 3/3\nusemtl b\nf 1/1 3/3 4/4\n");
    std::fs::write(dir.join("two.obj"), obj).unwrap();
    let meshes = kage::scene::load_obj(&dir.join("two.obj"), [1.0; 3]).unwrap();
    assert_eq!(meshes.iter().map(|m| m.name.as_str()).collect::<Vec<_>>(), ["two.0", "two.1"]);
    let (a, b) = (meshes[0].texturing.as_ref().unwrap(), meshes[1].texturing.as_ref().unwrap());
    assert_eq!((a.map.name.as_str(), b.map.name.as_str()), ("red.png", "blue.png"));
    assert_eq!(a.map.texels[0], [255, 0, 0, 255]);
    // vt 0 0 (the image's bottom-left in OBJ) is v = 1 in glTF's convention.
    assert_eq!(a.uvs[0], [0.0, 1.0]);

    std::fs::write(dir.join("lost.obj"), format!("mtllib nowhere.mtl\n{quad}usemtl a\nf 1/1 2/2 3/3\n"))
        .unwrap();
    let plain = kage::scene::load_obj(&dir.join("lost.obj"), [1.0; 3]).unwrap();
    assert!(plain.len() == 1 && plain[0].texturing.is_none());

    std::fs::write(dir.join("gone.mtl"), "newmtl a\nmap_Kd gone.png\n").unwrap();
    std::fs::write(dir.join("gone.obj"), format!("mtllib gone.mtl\n{quad}usemtl a\nf 1/1 2/2 3/3\n"))
        .unwrap();
    let error = kage::scene::load_obj(&dir.join("gone.obj"), [1.0; 3]).unwrap_err().to_string();
    assert!(error.contains("gone.png"), "{error}");
}

/// An exported textured scene reads back with its maps: as glTF (the map a PNG in the buffer,
/// its sampler, TEXCOORD_0) the box's mesh is equal, bit for bit; as OBJ (`vt`, a material
/// library and a PNG beside each OBJ) the texels are equal and the coordinates within f32
/// rounding of OBJ's 1 − v.
#[test]
fn textured_scenes_export_and_read_back() {
    use kage::scene::{SceneFormat, SCENE_FILE};
    let scene = box_on_floor(true);
    let original = &scene.groups[0].meshes[0];
    let (texturing, map) = (original.texturing.as_ref().unwrap(), &original.texturing.as_ref().unwrap().map);
    for format in [SceneFormat::Gltf, SceneFormat::Json] {
        let dir = scratch_dir("texture-export");
        scene.export(&dir, format).unwrap();
        let back = Scene::load(&dir.join(SCENE_FILE)).unwrap();
        let mesh = &back.groups[0].meshes[0];
        let read = mesh.texturing.as_ref().expect("the map comes back");
        assert_eq!(read.map.texels, map.texels, "{format:?}");
        match format {
            SceneFormat::Gltf => assert_eq!(mesh, original),
            SceneFormat::Json => {
                for (a, b) in read.uvs.iter().zip(&texturing.uvs) {
                    assert!((a[0] - b[0]).abs() <= 1e-6 && (a[1] - b[1]).abs() <= 1e-6, "{a:?} {b:?}");
                }
            }
        }
        assert!(back.groups[1].meshes[0].texturing.is_none(), "the floor has no map");
    }
}

/// Bad texturing in a glTF file is an error naming the file and what is wrong: a coordinate
/// set the primitive lacks, coordinates a texture transform makes infinite, an image that does
/// not decode.
#[test]
fn bad_texturing_is_refused_naming_the_file_and_the_problem() {
    let path =
        PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("assets/gltf/khronos-box-textured/BoxTextured.gltf");
    let original: serde_json::Value = serde_json::from_slice(&std::fs::read(&path).unwrap()).unwrap();
    let dir = scratch_dir("texture-hostile");
    let error_of = |name: &str, edit: &dyn Fn(&mut serde_json::Value)| {
        let mut gltf = original.clone();
        edit(&mut gltf);
        let file = dir.join(format!("{name}.gltf"));
        std::fs::write(&file, serde_json::to_vec(&gltf).unwrap()).unwrap();
        let message = Scene::load(&file).unwrap_err().to_string();
        assert!(message.contains(&format!("{name}.gltf")), "{message}");
        message
    };
    let texture = "/materials/0/pbrMetallicRoughness/baseColorTexture";
    let set = error_of("set", &|g| g.pointer_mut(texture).unwrap()["texCoord"] = 1.into());
    assert!(set.contains("reads TEXCOORD_1, which it does not have"), "{set}");
    let infinite = error_of("infinite", &|g| {
        g.pointer_mut(texture).unwrap()["extensions"] =
            serde_json::json!({"KHR_texture_transform": {"scale": [1e39, 1]}});
    });
    assert!(infinite.contains("texture coordinate") && infinite.contains("NaN or infinite"), "{infinite}");
    let image = error_of("image", &|g| g["images"][0]["uri"] = "data:image/png;base64,AAAA".into());
    assert!(image.contains("its base colour image 0: not a PNG or JPEG image Kage can read"), "{image}");
}
