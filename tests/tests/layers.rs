//! The modules' order in README's architecture block holds in the code: a module of
//! `engine/src` or `tools/src` names (through a `crate::` or `super::` path, test code
//! included) only modules on the block's lines above its own. The block is the one list; this
//! test reads it, so a new module must be placed there before it can import anything.
use std::collections::HashMap;
use std::path::{Path, PathBuf};

/// The repository's root.
fn root() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("..")
}

/// The modules the architecture block names, per source folder (`engine/src`, `tools/src`),
/// each with its line in the block.
fn block(readme: &str) -> HashMap<(String, String), usize> {
    let section = readme.split("\n## Architecture\n").nth(1).expect("README has an Architecture section");
    let code = section.split("```").nth(1).expect("the Architecture section opens with a code block");
    let mut modules = HashMap::new();
    for (line, text) in code.lines().enumerate() {
        let Some(dir) = ["engine/src/", "tools/src/"].into_iter().find(|d| text.starts_with(d)) else {
            continue;
        };
        // The names run up to the first gap of two spaces; the first carries the folder.
        let names = text.split("  ").next().unwrap_or_default();
        for name in names.split(", ") {
            let name = name.trim().trim_start_matches(dir).trim_end_matches('/').trim_end_matches(".rs");
            let key = (dir.trim_end_matches('/').to_string(), name.to_string());
            assert!(
                modules.insert(key, line).is_none(),
                "README's architecture block names {dir}{name} twice"
            );
        }
    }
    modules
}

/// `text` with comments, string and character literals blanked out, lengths kept.
fn code_only(text: &str) -> String {
    let b = text.as_bytes();
    let mut out = b.to_vec();
    let mut i = 0;
    let blank = |out: &mut Vec<u8>, from: usize, to: usize| {
        out[from..to].iter_mut().filter(|c| **c != b'\n').for_each(|c| *c = b' ')
    };
    while i < b.len() {
        let end = match (b[i], b.get(i + 1).copied()) {
            (b'/', Some(b'/')) => text[i..].find('\n').map_or(b.len(), |n| i + n),
            (b'/', Some(b'*')) => text[i + 2..].find("*/").map_or(b.len(), |n| i + 2 + n + 2),
            (b'"', _) => {
                let mut j = i + 1;
                while j < b.len() && b[j] != b'"' {
                    j += if b[j] == b'\\' { 2 } else { 1 };
                }
                j + 1
            }
            // A character literal ('x', '\n', '\''); a lifetime ('a) has no closing quote.
            (b'\'', Some(b'\\')) => text[i + 3..].find('\'').map_or(b.len(), |n| i + 3 + n + 1),
            (b'\'', Some(_)) if b.get(i + 2) == Some(&b'\'') => i + 3,
            _ => {
                i += 1;
                continue;
            }
        };
        let end = end.min(b.len());
        blank(&mut out, i, end);
        i = end;
    }
    String::from_utf8(out).expect("blanking keeps UTF-8 (whole characters replaced)")
}

fn is_ident(c: u8) -> bool {
    c.is_ascii_alphanumeric() || c == b'_'
}

/// The identifiers a path names right after `at`: one (`a::…`) or each of a group (`{a, b::c}`).
fn first_names(code: &str, at: usize) -> Vec<String> {
    let rest = code[at..].trim_start();
    if let Some(group) = rest.strip_prefix('{') {
        let mut depth = 0;
        let mut names = vec![];
        let mut item = String::new();
        for c in group.chars() {
            match c {
                '{' => depth += 1,
                '}' if depth == 0 => break,
                '}' => depth -= 1,
                ',' if depth == 0 => names.push(std::mem::take(&mut item)),
                _ => item.push(c),
            }
        }
        names.push(item);
        return names
            .iter()
            .filter_map(|n| {
                let n = n.trim();
                let end = n.bytes().position(|c| !is_ident(c)).unwrap_or(n.len());
                (end > 0).then(|| n[..end].to_string())
            })
            .collect();
    }
    let end = rest.bytes().position(|c| !is_ident(c)).unwrap_or(rest.len());
    if end == 0 {
        vec![]
    } else {
        vec![rest[..end].to_string()]
    }
}

/// The crate root's items a file of depth `depth` (its module path's length, `mod.rs` counting
/// as its folder) names through `crate::` paths and through `super::` chains that climb to the
/// root (inline `mod x { … }` blocks counted as one level each).
fn root_names(code: &str, depth: usize) -> Vec<String> {
    let b = code.as_bytes();
    let mut names = vec![];
    // The brace depths at which inline modules open.
    let (mut braces, mut inline): (usize, Vec<usize>) = (0, vec![]);
    let mut i = 0;
    while i < b.len() {
        let word_start = i == 0 || !is_ident(b[i - 1]);
        match b[i] {
            b'{' => braces += 1,
            b'}' => {
                braces -= 1;
                if inline.last() == Some(&braces) {
                    inline.pop();
                }
            }
            _ if word_start && code[i..].starts_with("mod ") => {
                let rest = &code[i + 4..];
                let name_end = rest.bytes().position(|c| !is_ident(c)).unwrap_or(rest.len());
                if rest[name_end..].trim_start().starts_with('{') {
                    inline.push(braces);
                }
            }
            _ if word_start && code[i..].starts_with("crate::") => {
                names.extend(first_names(code, i + "crate::".len()));
                i += "crate::".len();
                continue;
            }
            _ if word_start && code[i..].starts_with("super::") => {
                let mut climbs = 0;
                while code[i..].starts_with("super::") {
                    climbs += 1;
                    i += "super::".len();
                    i += code[i..].len() - code[i..].trim_start().len();
                }
                if climbs >= depth + inline.len() {
                    names.extend(first_names(code, i));
                }
                continue;
            }
            _ => {}
        }
        i += 1;
    }
    names
}

/// The `pub use module::{A, B}` re-exports at a crate root: item → module.
fn reexports(root_file: &str) -> HashMap<String, String> {
    let mut map = HashMap::new();
    for line in root_file.lines().filter_map(|l| l.trim().strip_prefix("pub use ")) {
        let Some((module, items)) = line.trim_end_matches(';').split_once("::") else { continue };
        for item in first_names(items, 0) {
            map.insert(item, module.to_string());
        }
    }
    map
}

fn rust_files(dir: &Path, out: &mut Vec<PathBuf>) {
    for entry in std::fs::read_dir(dir).unwrap_or_else(|e| panic!("{}: {e}", dir.display())) {
        let path = entry.expect("a readable folder entry").path();
        if path.is_dir() {
            rust_files(&path, out);
        } else if path.extension().is_some_and(|e| e == "rs") {
            out.push(path);
        }
    }
}

/// Every import that breaks the block's order, as "file: module → module" lines.
fn violations(src: &str, root_file: &str, blocks: &HashMap<(String, String), usize>) -> Vec<String> {
    let dir = root().join(src);
    let root_text = std::fs::read_to_string(dir.join(root_file)).expect("the crate root is readable");
    let reexported = reexports(&root_text);
    // The crate's modules: every file and folder beside the root file.
    let mut declared: Vec<String> = std::fs::read_dir(&dir)
        .expect("the source folder is readable")
        .map(|e| e.expect("a readable folder entry").file_name().to_string_lossy().into_owned())
        .filter(|name| name != root_file)
        .map(|name| name.trim_end_matches(".rs").to_string())
        .collect();
    declared.sort();
    let line_of = |module: &str| blocks.get(&(src.to_string(), module.to_string())).copied();
    let mut found = vec![];
    for module in &declared {
        if line_of(module).is_none() {
            found.push(format!("{src}/{module}: a module not placed in README's block"));
        }
    }
    let root_module = root_file.trim_end_matches(".rs");
    let mut files = vec![];
    rust_files(&dir, &mut files);
    files.sort();
    for file in files {
        let relative = file.strip_prefix(&dir).expect("below its folder");
        let parts: Vec<String> = relative.iter().map(|p| p.to_string_lossy().into_owned()).collect();
        let module = parts[0].trim_end_matches(".rs").to_string();
        if module == "lib" {
            continue; // declares the modules and re-exports; it imports nothing
        }
        let depth = if parts.last().is_some_and(|p| p == "mod.rs") { parts.len() - 1 } else { parts.len() };
        let text = std::fs::read_to_string(&file).expect("a readable source file");
        let Some(own) = line_of(&module) else { continue };
        for name in root_names(&code_only(&text), depth) {
            let target = if declared.contains(&name) {
                name
            } else if let Some(m) = reexported.get(&name) {
                m.clone()
            } else {
                root_module.to_string()
            };
            if target == module {
                continue;
            }
            match line_of(&target) {
                Some(line) if line < own => {}
                _ => found.push(format!("{src}/{}: {module} imports {target}", relative.display())),
            }
        }
    }
    found.sort();
    found.dedup();
    found
}

#[test]
fn modules_import_only_what_readme_places_below_them() {
    let readme = std::fs::read_to_string(root().join("README.md")).expect("README.md is readable");
    let blocks = block(&readme);
    let mut found = violations("engine/src", "lib.rs", &blocks);
    found.extend(violations("tools/src", "main.rs", &blocks));
    assert!(found.is_empty(), "imports against README's architecture block:\n{}", found.join("\n"));
}

/// The reader finds imports in every form the code uses, and none in comments or strings.
#[test]
fn imports_are_found_in_paths_groups_and_super_chains() {
    let code = code_only(
        "use crate::{backend::Cmd, error::Error};\n// crate::capi\nlet s = \"crate::renderer\";\n\
         let c = '{'; fn f<'a>(x: &'a crate::frame::X) {}\nmod tests { use super::*; use super::super::sh; }",
    );
    assert_eq!(root_names(&code, 1), ["backend", "error", "frame", "sh"]);
    // In a file one level down the same `super::super` stays inside its module.
    assert_eq!(root_names(&code, 2), ["backend", "error", "frame"]);
    let readme = "x\n## Architecture\n\n```\nengine/src/a.rs, b/   what\nengine/src/c/  more\n```\n";
    let placed = block(readme);
    assert_eq!(placed[&("engine/src".into(), "b".into())], 1);
    assert_eq!(placed[&("engine/src".into(), "c".into())], 2);
}
