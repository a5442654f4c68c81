//! The `struct`s of `shaders-glsl/include/layouts.glsl` as `#[repr(C)]` Rust structs with std430
//! offsets in `$OUT_DIR/layouts.rs`, with compile-time size and offset assertions.
use crate::constants::Constant;
use crate::read;
use std::collections::HashMap;
use std::fmt::Write as _;
use std::path::Path;

#[derive(Clone)]
enum Type {
    /// A GLSL scalar, vector or matrix: its Rust type, std430 size and alignment.
    Basic {
        rust: &'static str,
        size: u32,
        align: u32,
    },
    Struct {
        name: String,
        size: u32,
        align: u32,
    },
    Array(Box<Type>, u32),
}

impl Type {
    fn size(&self) -> u32 {
        match self {
            Type::Basic { size, .. } | Type::Struct { size, .. } => *size,
            Type::Array(element, n) => element.size() * n,
        }
    }

    fn align(&self) -> u32 {
        match self {
            Type::Basic { align, .. } | Type::Struct { align, .. } => *align,
            Type::Array(element, _) => element.align(),
        }
    }

    fn rust(&self) -> String {
        match self {
            Type::Basic { rust, .. } => rust.to_string(),
            Type::Struct { name, .. } => name.clone(),
            Type::Array(element, n) => format!("[{}; {n}]", element.rust()),
        }
    }

    /// Whether `#[derive(Default)]` works: std implements `Default` only for arrays up to 32.
    fn derives_default(&self) -> bool {
        match self {
            Type::Basic { .. } | Type::Struct { .. } => true,
            Type::Array(element, n) => *n <= 32 && element.derives_default(),
        }
    }

    fn default_expr(&self) -> String {
        match self {
            Type::Basic { .. } | Type::Struct { .. } => "Default::default()".to_string(),
            Type::Array(element, n) => format!("[{}; {n}]", element.default_expr()),
        }
    }
}

fn basic_type(glsl: &str) -> Option<Type> {
    let (rust, size, align) = match glsl {
        "float" => ("f32", 4, 4),
        "int" => ("i32", 4, 4),
        "uint" => ("u32", 4, 4),
        "vec2" => ("[f32; 2]", 8, 8),
        "vec4" => ("[f32; 4]", 16, 16),
        "ivec4" => ("[i32; 4]", 16, 16),
        "uvec4" => ("[u32; 4]", 16, 16),
        // Column-major, as glam's `Mat4::to_cols_array_2d`.
        "mat4" => ("[[f32; 4]; 4]", 64, 16),
        _ => return None,
    };
    Some(Type::Basic { rust, size, align })
}

struct Member {
    name: String,
    ty: Type,
    offset: u32,
    doc: Vec<String>,
}

struct Struct {
    name: String,
    doc: Vec<String>,
    members: Vec<Member>,
    size: u32,
    align: u32,
}

#[derive(PartialEq)]
enum Token {
    Word(String),
    Punct(char),
    /// A comment's text and its last line.
    Comment(String, usize),
}

/// Tokens with their line numbers; preprocessor lines are skipped (the include guard and the
/// `#include` of constants.glsl).
fn tokenize(text: &str, at: &dyn Fn(usize) -> String) -> Result<Vec<(Token, usize)>, String> {
    let mut tokens = Vec::new();
    let chars: Vec<char> = text.chars().collect();
    let (mut i, mut line) = (0, 1);
    let mut line_start = true;
    while i < chars.len() {
        let c = chars[i];
        if c == '\n' {
            line += 1;
            line_start = true;
            i += 1;
            continue;
        }
        if c.is_whitespace() {
            i += 1;
            continue;
        }
        if line_start && c == '#' {
            while i < chars.len() && chars[i] != '\n' {
                i += 1;
            }
            continue;
        }
        line_start = false;
        let start_line = line;
        if c == '/' && chars.get(i + 1) == Some(&'/') {
            let end = chars[i..].iter().position(|&c| c == '\n').map_or(chars.len(), |p| i + p);
            tokens.push((Token::Comment(chars[i + 2..end].iter().collect(), line), start_line));
            i = end;
        } else if c == '/' && chars.get(i + 1) == Some(&'*') {
            let body_start = i + 2;
            let mut j = body_start;
            while j + 1 < chars.len() && !(chars[j] == '*' && chars[j + 1] == '/') {
                line += (chars[j] == '\n') as usize;
                j += 1;
            }
            if j + 1 >= chars.len() {
                return Err(format!("{}: unterminated comment", at(start_line)));
            }
            tokens.push((Token::Comment(chars[body_start..j].iter().collect(), line), start_line));
            i = j + 2;
        } else if c.is_alphanumeric() || c == '_' {
            let end = chars[i..]
                .iter()
                .position(|&c| !(c.is_alphanumeric() || c == '_'))
                .map_or(chars.len(), |p| i + p);
            tokens.push((Token::Word(chars[i..end].iter().collect()), start_line));
            i = end;
        } else if "{};[]".contains(c) {
            tokens.push((Token::Punct(c), start_line));
            i += 1;
        } else {
            return Err(format!("{}: unexpected `{c}`; only plain struct definitions belong here", at(line)));
        }
    }
    Ok(tokens)
}

fn comment_lines(text: &str) -> impl Iterator<Item = String> + '_ {
    text.lines().map(|l| l.trim().trim_start_matches('*').trim().to_string()).filter(|l| !l.is_empty())
}

struct Parser<'a> {
    tokens: Vec<(Token, usize)>,
    pos: usize,
    at: &'a dyn Fn(usize) -> String,
}

impl Parser<'_> {
    fn line(&self) -> usize {
        self.tokens.get(self.pos).or(self.tokens.last()).map_or(1, |t| t.1)
    }

    fn error(&self, message: impl std::fmt::Display) -> String {
        format!("{}: {message}", (self.at)(self.line()))
    }

    fn word(&mut self, what: &str) -> Result<String, String> {
        match self.tokens.get(self.pos) {
            Some((Token::Word(w), _)) => {
                self.pos += 1;
                Ok(w.clone())
            }
            _ => Err(self.error(format!("expected {what}"))),
        }
    }

    fn punct(&mut self, c: char) -> Result<(), String> {
        if self.tokens.get(self.pos).map(|t| &t.0) == Some(&Token::Punct(c)) {
            self.pos += 1;
            Ok(())
        } else {
            Err(self.error(format!("expected `{c}`")))
        }
    }

    fn peek_punct(&self, c: char) -> bool {
        self.tokens.get(self.pos).map(|t| &t.0) == Some(&Token::Punct(c))
    }
}

// GLSL accepts these as member names; generated Rust would not compile.
const RUST_KEYWORDS: &[&str] = &[
    "as", "async", "await", "box", "crate", "dyn", "fn", "gen", "impl", "let", "loop", "match", "mod",
    "move", "mut", "pub", "ref", "self", "Self", "super", "trait", "type", "unsafe", "use", "where", "yield",
    "abstract", "become", "final", "macro", "override", "priv", "try", "typeof", "unsized", "virtual",
];

fn parse_structs(path: &Path, constants: &HashMap<String, Constant>) -> Result<Vec<Struct>, String> {
    let text = read(path)?;
    let at = |line: usize| format!("{}:{line}", path.display());
    let mut p = Parser { tokens: tokenize(&text, &at)?, pos: 0, at: &at };
    let mut structs: Vec<Struct> = Vec::new();
    // Only the comment lines directly above a struct document it, not a file's header.
    let mut doc = Vec::new();
    let mut doc_end = 0;
    while let Some((token, line)) = p.tokens.get(p.pos) {
        if *line != doc_end + 1 {
            doc.clear();
        }
        if let Token::Comment(c, end) = token {
            doc.extend(comment_lines(c));
            doc_end = *end;
            p.pos += 1;
            continue;
        }
        if p.word("`struct`")? != "struct" {
            p.pos -= 1;
            return Err(p.error("expected `struct`; layouts.glsl holds only struct definitions"));
        }
        let name = p.word("a struct name")?;
        if structs.iter().any(|s| s.name == name) || basic_type(&name).is_some() {
            p.pos -= 1;
            return Err(p.error(format!("`{name}` is already defined")));
        }
        p.punct('{')?;
        let mut members: Vec<Member> = Vec::new();
        let mut member_doc = Vec::new();
        let mut last_member_line = 0;
        let (mut offset, mut align) = (0u32, 1u32);
        loop {
            let (token, line) = p.tokens.get(p.pos).ok_or_else(|| p.error("unterminated struct"))?;
            match token {
                Token::Punct('}') => break,
                // A comment on a member's own line describes that member, others the next one.
                Token::Comment(c, _) if *line == last_member_line => {
                    members.last_mut().unwrap().doc.extend(comment_lines(c));
                    p.pos += 1;
                    continue;
                }
                Token::Comment(c, _) => {
                    member_doc.extend(comment_lines(c));
                    p.pos += 1;
                    continue;
                }
                _ => {}
            }
            let type_name = p.word("a member type")?;
            let mut ty = match basic_type(&type_name) {
                Some(ty) => ty,
                None if matches!(type_name.as_str(), "vec3" | "ivec3" | "uvec3" | "mat3") => {
                    p.pos -= 1;
                    return Err(p.error(format!(
                        "`{type_name}` is not allowed: std140/std430 align a 3-vector to 16 bytes \
                         but a following scalar packs into its 4th slot, a layout trap between GLSL \
                         and Rust; use the 4-component type and leave .w unused"
                    )));
                }
                None => match structs.iter().find(|s| s.name == type_name) {
                    // std140 aligns a nested struct to 16; demanding it in std430 too keeps
                    // the two layouts identical.
                    Some(s) if s.align % 16 != 0 => {
                        p.pos -= 1;
                        return Err(p.error(format!(
                            "`{type_name}` has a 4-byte or 8-byte alignment, so its offset as a \
                             member differs between std140 and std430; give it a vec4 or mat4 member"
                        )));
                    }
                    Some(s) => Type::Struct { name: s.name.clone(), size: s.size, align: s.align },
                    None => {
                        p.pos -= 1;
                        return Err(p.error(format!(
                            "unknown member type `{type_name}` (supported: float, int, uint, vec2, \
                             vec4, ivec4, uvec4, mat4 and structs defined above)"
                        )));
                    }
                },
            };
            let member_line = p.line();
            let name = p.word("a member name")?;
            if name.starts_with('_') || RUST_KEYWORDS.contains(&name.as_str()) {
                p.pos -= 1;
                return Err(p.error(format!(
                    "member name `{name}` is reserved in the generated Rust (`_` prefix or Rust keyword)"
                )));
            }
            if members.iter().any(|m| m.name == name) {
                p.pos -= 1;
                return Err(p.error(format!("member `{name}` is defined twice")));
            }
            if p.peek_punct('[') {
                p.pos += 1;
                if matches!(type_name.as_str(), "float" | "int" | "uint" | "vec2") {
                    return Err(p.error(format!(
                        "arrays of `{type_name}` have a 16-byte stride in std140 but not in std430; \
                         use an array of vec4/ivec4/uvec4 instead"
                    )));
                }
                let size = p.word("an array size")?;
                let n = match (size.parse::<u32>(), constants.get(&size)) {
                    (Ok(n), _) | (_, Some(&Constant::U32(n))) => n,
                    _ => {
                        return Err(p.error(format!(
                            "array size `{size}` is neither an integer literal nor an integer \
                             constant from constants.glsl"
                        )))
                    }
                };
                if n == 0 {
                    return Err(p.error("arrays must not be empty"));
                }
                p.punct(']')?;
                ty = Type::Array(Box::new(ty), n);
            }
            p.punct(';')?;
            offset = offset.next_multiple_of(ty.align());
            align = align.max(ty.align());
            let size = ty.size();
            members.push(Member { name, ty, offset, doc: std::mem::take(&mut member_doc) });
            offset += size;
            last_member_line = member_line;
        }
        p.punct('}')?;
        p.punct(';')?;
        if members.is_empty() {
            return Err(p.error(format!("struct `{name}` is empty")));
        }
        let size = offset.next_multiple_of(align);
        structs.push(Struct { name, doc: std::mem::take(&mut doc), members, size, align });
    }
    Ok(structs)
}

pub fn generate_layouts(path: &Path, constants: &HashMap<String, Constant>) -> Result<String, String> {
    let structs = parse_structs(path, constants)?;
    let mut rust =
        String::from("// Generated by engine/build/ from shaders-glsl/include/layouts.glsl: do not edit.\n");
    for s in &structs {
        let name = &s.name;
        // Every padding byte is an explicit field, so `bytes_of` never exposes uninitialised
        // memory; the size assertion below (size == sum of fields) holds the generator to it.
        let mut fields = Vec::new();
        let mut offset = 0;
        let mut pad = 0;
        let mut push_pad = |fields: &mut Vec<(String, String, Vec<String>)>, from: u32, to: u32| {
            if to > from {
                fields.push((format!("_pad{pad}"), format!("[u32; {}]", (to - from) / 4), Vec::new()));
                pad += 1;
            }
        };
        for m in &s.members {
            push_pad(&mut fields, offset, m.offset);
            fields.push((m.name.clone(), m.ty.rust(), m.doc.clone()));
            offset = m.offset + m.ty.size();
        }
        push_pad(&mut fields, offset, s.size);

        writeln!(rust).unwrap();
        for d in &s.doc {
            writeln!(rust, "/// {d}").unwrap();
        }
        if !s.doc.is_empty() {
            writeln!(rust, "///").unwrap();
        }
        writeln!(
            rust,
            "/// std430 size {}, alignment {}; defined in `shaders-glsl/include/layouts.glsl`.",
            s.size, s.align
        )
        .unwrap();
        let derive_default = s.members.iter().all(|m| m.ty.derives_default());
        let derives = if derive_default {
            "Clone, Copy, Debug, Default, PartialEq"
        } else {
            "Clone, Copy, Debug, PartialEq"
        };
        writeln!(rust, "#[repr(C)]\n#[derive({derives})]\npub struct {name} {{").unwrap();
        for (field, ty, doc) in &fields {
            for d in doc {
                writeln!(rust, "    /// {d}").unwrap();
            }
            let vis = if field.starts_with('_') { "" } else { "pub " };
            writeln!(rust, "    {vis}{field}: {ty},").unwrap();
        }
        writeln!(rust, "}}\n").unwrap();

        if !derive_default {
            writeln!(rust, "impl Default for {name} {{\n    fn default() -> Self {{\n        Self {{")
                .unwrap();
            for (field, _, _) in &fields {
                let expr = match s.members.iter().find(|m| &m.name == field) {
                    Some(m) => m.ty.default_expr(),
                    None => "Default::default()".to_string(),
                };
                writeln!(rust, "            {field}: {expr},").unwrap();
            }
            writeln!(rust, "        }}\n    }}\n}}\n").unwrap();
        }

        writeln!(
            rust,
            "impl {name} {{\n    /// The bytes to copy into a buffer or push constants.\n    \
             pub fn as_bytes(&self) -> &[u8] {{\n        bytes_of(self)\n    }}\n}}\n"
        )
        .unwrap();
        writeln!(rust, "impl sealed::Sealed for {name} {{}}\nimpl Pod for {name} {{}}\n").unwrap();

        writeln!(rust, "const _: () = assert!(std::mem::size_of::<{name}>() == {});", s.size).unwrap();
        let field_sizes: Vec<String> =
            fields.iter().map(|(_, ty, _)| format!("std::mem::size_of::<{ty}>()")).collect();
        writeln!(rust, "const _: () = assert!({} == {});", field_sizes.join(" + "), s.size).unwrap();
        for m in &s.members {
            writeln!(
                rust,
                "const _: () = assert!(std::mem::offset_of!({name}, {}) == {});",
                m.name, m.offset
            )
            .unwrap();
        }
    }
    Ok(rust)
}
