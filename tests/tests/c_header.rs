//! The committed C header is what cbindgen makes of the C ABI today. On a difference the test
//! fails; `KAGE_BLESS=1` rewrites the header instead (then review and commit it).
use std::path::Path;

#[test]
fn committed_header_matches_the_c_abi() {
    let engine = Path::new(env!("CARGO_MANIFEST_DIR")).join("../engine");
    let config = cbindgen::Config::from_file(engine.join("cbindgen.toml")).expect("engine/cbindgen.toml");
    let bindings = cbindgen::Builder::new()
        .with_crate(&engine)
        .with_config(config)
        .generate()
        .expect("cbindgen parses engine/src/capi");
    let mut fresh = Vec::new();
    bindings.write(&mut fresh);
    let path = engine.join("include/kage.h");
    if std::env::var_os("KAGE_BLESS").is_some_and(|v| v == "1") {
        std::fs::write(&path, &fresh).expect("writing engine/include/kage.h");
        return;
    }
    let committed = std::fs::read(&path).unwrap_or_default();
    assert!(
        committed == fresh,
        "engine/include/kage.h is not what cbindgen generates from engine/src/capi/; regenerate it with\n  \
         KAGE_BLESS=1 cargo test --release -p kage-tests --test c_header\nand commit it"
    );
}

/// C++ hosts (game engines) include the same header.
#[test]
fn header_compiles_as_cpp() {
    let header = Path::new(env!("CARGO_MANIFEST_DIR")).join("../engine/include/kage.h");
    let output = std::process::Command::new("c++")
        .args(["-std=c++17", "-fsyntax-only", "-Wall", "-Wextra", "-Werror", "-pedantic", "-x", "c++"])
        .arg(&header)
        .output()
        .expect("c++ (Debian: g++)");
    assert!(output.status.success(), "kage.h as C++:\n{}", String::from_utf8_lossy(&output.stderr));
}

/// README's C example, the first ```c block of its C ABI section, compiles as C11 with every
/// warning an error (tests/tests/c_hosts.rs also links and runs it as README says).
#[test]
fn the_readme_c_example_compiles() {
    let repo = Path::new(env!("CARGO_MANIFEST_DIR")).join("..");
    let dir = kage_tests::scratch_dir("readme-c");
    let source = dir.join("example.c");
    std::fs::write(&source, kage_tests::readme_block("## C ABI", "c")).unwrap();
    let output = std::process::Command::new("cc")
        .args(["-std=c11", "-fsyntax-only", "-Wall", "-Wextra", "-Werror", "-pedantic", "-I"])
        .arg(repo.join("engine/include"))
        .arg(&source)
        .output()
        .expect("cc (Debian: gcc)");
    assert!(output.status.success(), "README's C example:\n{}", String::from_utf8_lossy(&output.stderr));
}

/// A host uses every enumeration value and every struct field by name (tests/c_host/names.c):
/// it compiles as strict C11 and as C++17.
#[test]
fn every_name_compiles_in_c_and_cpp() {
    let repo = Path::new(env!("CARGO_MANIFEST_DIR")).join("..");
    let include = repo.join("engine/include");
    let source = repo.join("tests/c_host/names.c");
    for (compiler, standard) in [("cc", "-std=c11"), ("c++", "-std=c++17")] {
        let mut command = std::process::Command::new(compiler);
        command
            .args([standard, "-fsyntax-only", "-Wall", "-Wextra", "-Werror", "-pedantic"])
            .arg("-I")
            .arg(&include);
        if compiler == "c++" {
            command.args(["-x", "c++"]);
        }
        let output = command.arg(&source).output().expect("cc and c++ (Debian: gcc, g++)");
        assert!(
            output.status.success(),
            "names.c with {compiler} {standard}:\n{}",
            String::from_utf8_lossy(&output.stderr)
        );
    }
}
