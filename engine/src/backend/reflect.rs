//! The descriptor bindings a SPIR-V module uses, read from its instructions, so that every
//! pipeline's declared bindings are checked against its shaders when the pipeline is made: a
//! wrong binding list fails there, naming the shader and the binding, not as a validation
//! message at draw time. Only what Kage's shaders use is read: set 0, uniform and storage
//! buffers, combined image samplers, texel buffers and storage images, and whether the shader may write each
//! (what a pass that binds it touches: `access.rs`).
use super::descriptor::BindingKind;
use std::collections::HashMap;

const OP_TYPE_IMAGE: u32 = 25;
const OP_TYPE_SAMPLED_IMAGE: u32 = 27;
const OP_TYPE_ARRAY: u32 = 28;
const OP_TYPE_RUNTIME_ARRAY: u32 = 29;
const OP_TYPE_STRUCT: u32 = 30;
const OP_TYPE_POINTER: u32 = 32;
const OP_VARIABLE: u32 = 59;
const OP_DECORATE: u32 = 71;
const OP_MEMBER_DECORATE: u32 = 72;
const DECORATION_BLOCK: u32 = 2;
const DECORATION_BUFFER_BLOCK: u32 = 3;
const DECORATION_NON_WRITABLE: u32 = 24;
const DECORATION_BINDING: u32 = 33;
const DECORATION_DESCRIPTOR_SET: u32 = 34;
const STORAGE_UNIFORM_CONSTANT: u32 = 0;
const STORAGE_UNIFORM: u32 = 2;
const STORAGE_STORAGE_BUFFER: u32 = 12;
/// `OpTypeImage`'s "sampled" operand for an image used without a sampler (a storage image).
const IMAGE_STORAGE: u32 = 2;
/// `OpTypeImage`'s dimensionality of a texel buffer.
const DIM_BUFFER: u32 = 5;

/// A descriptor a shader uses.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Used {
    pub binding: u32,
    pub kind: BindingKind,
    /// Whether the shader may write it: a storage buffer or image not declared `readonly`.
    pub written: bool,
}

/// Every descriptor of set 0 the module uses, by binding; `Err` names an instruction this
/// reader does not know how to classify.
pub fn descriptor_bindings(words: &[u32]) -> Result<Vec<Used>, String> {
    let mut decorations: HashMap<u32, Vec<(u32, u32)>> = HashMap::new();
    // Per struct: its member count and how many members are `NonWritable`.
    let mut members: HashMap<u32, (usize, usize)> = HashMap::new();
    let mut types: HashMap<u32, (u32, Vec<u32>)> = HashMap::new();
    let mut variables = Vec::new();
    let mut at = 5; // past the header
    while at < words.len() {
        let (count, opcode) = ((words[at] >> 16) as usize, words[at] & 0xffff);
        if count == 0 || at + count > words.len() {
            return Err(format!("malformed instruction at word {at}"));
        }
        let operands = &words[at + 1..at + count];
        match opcode {
            OP_DECORATE if operands.len() >= 2 => {
                let value = operands.get(2).copied().unwrap_or(0);
                decorations.entry(operands[0]).or_default().push((operands[1], value));
            }
            OP_MEMBER_DECORATE if operands.len() >= 3 && operands[2] == DECORATION_NON_WRITABLE => {
                members.entry(operands[0]).or_default().1 += 1;
            }
            OP_TYPE_STRUCT if !operands.is_empty() => {
                members.entry(operands[0]).or_default().0 = operands.len() - 1
            }
            OP_VARIABLE if operands.len() >= 3 => variables.push((operands[1], operands[0], operands[2])),
            OP_TYPE_IMAGE
            | OP_TYPE_SAMPLED_IMAGE
            | OP_TYPE_ARRAY
            | OP_TYPE_RUNTIME_ARRAY
            | OP_TYPE_POINTER
                if !operands.is_empty() =>
            {
                types.insert(operands[0], (opcode, operands[1..].to_vec()));
            }
            _ => {}
        }
        at += count;
    }
    let decoration = |id: u32, which: u32| {
        decorations.get(&id).and_then(|d| d.iter().find(|(k, _)| *k == which)).map(|(_, v)| *v)
    };
    let has = |id: u32, which: u32| decoration(id, which).is_some();
    let mut found = Vec::new();
    for (id, pointer, storage) in variables {
        let Some(binding) = decoration(id, DECORATION_BINDING) else { continue };
        if decoration(id, DECORATION_DESCRIPTOR_SET).unwrap_or(0) != 0 {
            continue;
        }
        // The pointee, through descriptor arrays to their element.
        let mut pointee = types.get(&pointer).and_then(|(_, ops)| ops.get(1).copied()).unwrap_or(0);
        while let Some((OP_TYPE_ARRAY | OP_TYPE_RUNTIME_ARRAY, ops)) = types.get(&pointee) {
            pointee = ops[0];
        }
        let kind = match (storage, types.get(&pointee)) {
            (STORAGE_STORAGE_BUFFER, _) => BindingKind::StorageBuffer,
            (STORAGE_UNIFORM, _) if has(pointee, DECORATION_BUFFER_BLOCK) => BindingKind::StorageBuffer,
            (STORAGE_UNIFORM, _) if has(pointee, DECORATION_BLOCK) => BindingKind::UniformBuffer,
            (STORAGE_UNIFORM_CONSTANT, Some((OP_TYPE_SAMPLED_IMAGE, ops))) => {
                match ops.first().and_then(|image| types.get(image)) {
                    Some((OP_TYPE_IMAGE, image)) if image.get(1) == Some(&DIM_BUFFER) => {
                        BindingKind::TexelBuffer
                    }
                    _ => BindingKind::SampledImage,
                }
            }
            (STORAGE_UNIFORM_CONSTANT, Some((OP_TYPE_IMAGE, ops))) if ops.get(5) == Some(&IMAGE_STORAGE) => {
                match ops.get(1) == Some(&DIM_BUFFER) {
                    true => BindingKind::StorageTexelBuffer,
                    false => BindingKind::StorageImage,
                }
            }
            _ => return Err(format!("binding {binding}: a descriptor of a kind Kage does not use")),
        };
        let readonly = has(id, DECORATION_NON_WRITABLE)
            || members.get(&pointee).is_some_and(|&(count, read_only)| count > 0 && read_only == count);
        let written = matches!(
            kind,
            BindingKind::StorageBuffer | BindingKind::StorageImage | BindingKind::StorageTexelBuffer
        ) && !readonly;
        found.push(Used { binding, kind, written });
    }
    found.sort_by_key(|u| u.binding);
    Ok(found)
}

/// Checks that every binding `used` by the shader `shader` is declared in `declared` (the
/// pipeline's list, in binding order) with the same kind.
pub fn check(shader: &str, declared: &[BindingKind], used: &[Used]) -> Result<(), String> {
    for &Used { binding, kind, .. } in used {
        match declared.get(binding as usize) {
            Some(&d) if d == kind => {}
            Some(d) => {
                return Err(format!(
                    "{shader} uses binding {binding} as {kind:?}, the pipeline declares it as {d:?}"
                ))
            }
            None => {
                return Err(format!(
                    "{shader} uses binding {binding} ({kind:?}), the pipeline declares {} bindings",
                    declared.len()
                ))
            }
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::layouts::{constants, spirv};
    use BindingKind::{
        SampledImage, StorageBuffer, StorageImage, StorageTexelBuffer, TexelBuffer, UniformBuffer,
    };

    fn used(spirv: &[u8]) -> Vec<Used> {
        descriptor_bindings(&ash::util::read_spv(&mut std::io::Cursor::new(spirv)).unwrap()).unwrap()
    }

    fn kinds(spirv: &[u8]) -> Vec<(u32, BindingKind, bool)> {
        used(spirv).iter().map(|u| (u.binding, u.kind, u.written)).collect()
    }

    /// Each kind, read from Kage's own shaders (their GLSL declares these bindings), and
    /// whether the shader writes it: only storage buffers and images not declared `readonly`.
    #[test]
    fn the_shaders_bindings_are_read_with_their_kinds() {
        assert_eq!(kinds(spirv::BACKGROUND_FRAG), [(0, UniformBuffer, false), (1, SampledImage, false)]);
        assert_eq!(
            kinds(spirv::OCCLUSION_BLUR_COMP),
            [
                (0, StorageBuffer, false),
                (1, SampledImage, false),
                (2, StorageBuffer, true),
                (3, StorageImage, true)
            ]
        );
        // ASM's packing reads the scratch and its list of slots and pages, and writes pages.
        assert_eq!(
            kinds(spirv::ASM_PACK_COMP),
            [(0, SampledImage, false), (1, StorageBuffer, false), (2, StorageTexelBuffer, true)]
        );
        // The ray caster reads the BVH's traversal data, triangle attributes and rays as texel
        // buffers, its albedo maps as storage buffers, and writes only its results.
        assert_eq!(
            kinds(spirv::RAYCAST_COMP),
            [
                (0, TexelBuffer, false),
                (1, TexelBuffer, false),
                (2, TexelBuffer, false),
                (3, TexelBuffer, false),
                (4, TexelBuffer, false),
                (5, StorageBuffer, false),
                (6, StorageBuffer, false),
                (7, TexelBuffer, false),
                (8, StorageBuffer, true)
            ]
        );
        // The transfer shader reads the BVH and the vertices and writes its sums.
        let prt = used(spirv::PRT_TRANSFER_COMP);
        let written: Vec<u32> = prt.iter().filter(|u| u.written).map(|u| u.binding).collect();
        let first = constants::BVH_BINDINGS;
        assert_eq!(written, [first + 1, first + 2, first + 3]);
    }

    #[test]
    fn a_wrong_or_short_list_is_an_error_naming_the_binding() {
        let background = used(spirv::BACKGROUND_FRAG);
        assert!(check("background.frag", &[UniformBuffer, SampledImage], &background).is_ok());
        let wrong = check("background.frag", &[UniformBuffer, StorageBuffer], &background).unwrap_err();
        assert!(wrong.contains("binding 1 as SampledImage") && wrong.contains("StorageBuffer"), "{wrong}");
        let short = check("background.frag", &[UniformBuffer], &background).unwrap_err();
        assert!(short.contains("binding 1") && short.contains("declares 1 bindings"), "{short}");
    }
}
