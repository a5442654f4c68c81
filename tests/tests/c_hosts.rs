//! The C hosts in tests/c_host/, compiled with `cc` against engine/include/kage.h and the
//! engine's staticlib and cdylib from this same cargo build: first on the default device with
//! validation on, then under valgrind memcheck.
use std::path::{Path, PathBuf};
use std::process::{Command, Output};
use std::sync::OnceLock;
use std::time::Instant;

fn repo() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("..")
}

/// Where cargo put this test's libraries: the test runs from `<target>/<profile>/deps/`, and
/// the engine's staticlib and cdylib sit in `<target>/<profile>/`.
fn library(name: &str) -> PathBuf {
    let exe = std::env::current_exe().expect("the test executable's path");
    let dir = exe.parent().and_then(Path::parent).expect("<target>/<profile>/deps/<test>");
    let path = dir.join(name);
    assert!(
        path.exists(),
        "{} is missing: `cargo test` does not make the engine's staticlib and cdylib; run `cargo build --release -p kage` first (scripts/test.sh does)",
        path.display()
    );
    path
}

/// The two hosts, compiled once per test run.
struct Hosts {
    /// Builds a scene from arrays and checks every function's bad-argument codes; linked with
    /// libkage.a.
    arrays: PathBuf,
    /// Creates its own Vulkan device and hands it to Kage; linked with libkage.so.
    vulkan: PathBuf,
    /// Calls Kage from several threads at once and uses destroyed handles; linked with
    /// libkage.a.
    threads: PathBuf,
}

fn hosts() -> &'static Hosts {
    static HOSTS: OnceLock<Hosts> = OnceLock::new();
    HOSTS.get_or_init(|| {
        let dir = kage_tests::scratch_dir("c_hosts");
        let src = repo().join("tests/c_host");
        let compile = |name: &str, link: &[&str]| {
            let out = dir.join(name);
            let mut cc = Command::new("cc");
            cc.args(["-std=c11", "-g", "-Wall", "-Wextra", "-Werror", "-pedantic"])
                .arg("-I")
                .arg(repo().join("engine/include"))
                .arg(src.join(format!("{name}.c")))
                .arg("-o")
                .arg(&out)
                .args(link);
            succeeded(&format!("cc {name}.c"), cc.output().expect("cc (Debian: gcc)"));
            out
        };
        let staticlib = library("libkage.a").display().to_string();
        // The cdylib's SONAME names the ABI version (libkage.so.1), which the host then needs
        // at run time: a link by that name beside the hosts, as an install would make it.
        let cdylib = library("libkage.so");
        let soname = dir.join(soname());
        let _ = std::fs::remove_file(&soname);
        std::os::unix::fs::symlink(&cdylib, &soname).expect("the SONAME link beside the hosts");
        let cdylib_dir = cdylib.parent().expect("folder").display().to_string();
        let rpath = format!("-Wl,-rpath,{}", dir.display());
        let common = src.join("common.c").display().to_string();
        // After the archive, the system libraries Rust's standard library needs (what
        // `rustc --print native-static-libs` lists for linux-gnu).
        let with_staticlib = |name| {
            compile(
                name,
                &[&common, &staticlib, "-lgcc_s", "-lutil", "-lrt", "-lpthread", "-lm", "-ldl", "-lc"],
            )
        };
        Hosts {
            arrays: with_staticlib("arrays"),
            vulkan: compile("vulkan", &[&common, &format!("-L{cdylib_dir}"), "-lkage", &rpath, "-lvulkan"]),
            threads: with_staticlib("threads"),
        }
    })
}

/// The SONAME libkage.so must carry: the ABI version the library reports.
fn soname() -> String {
    format!("libkage.so.{}", kage::capi::kage_abi_version())
}

/// The library's SONAME is its ABI version, so that the loader refuses a library of another.
#[test]
fn the_shared_library_is_named_for_its_abi_version() {
    let output =
        Command::new("readelf").arg("-d").arg(library("libkage.so")).output().expect("readelf (binutils)");
    let dynamic = succeeded("readelf -d libkage.so", output);
    assert!(dynamic.contains(&format!("Library soname: [{}]", soname())), "{dynamic}");
}

#[track_caller]
fn succeeded(what: &str, output: Output) -> String {
    let stdout = String::from_utf8_lossy(&output.stdout).into_owned();
    let stderr = String::from_utf8_lossy(&output.stderr);
    assert!(output.status.success(), "{what} failed ({}):\n{stdout}\n{stderr}", output.status);
    stdout
}

/// The full runs: 10 frames at 64², validation on. Tamura through the arrays host, Sloan
/// through the host's own device (techniques as numbered in kage.h).
#[test]
fn c_hosts_run_with_validation() {
    let hosts = hosts();
    let out =
        succeeded("arrays host", Command::new(&hosts.arrays).args(["10", "64", "1", "2"]).output().unwrap());
    assert!(out.contains("frame 9:") && out.ends_with("ok\n"), "{out}");
    let out =
        succeeded("vulkan host", Command::new(&hosts.vulkan).args(["10", "64", "1", "1"]).output().unwrap());
    assert!(out.contains("frame 9:") && out.ends_with("ok\n"), "{out}");
}

/// README's "Building a host": its commands run verbatim in a folder holding README's C
/// example as host.c, with `KAGE` this repository; the host it links renders the teapot and
/// prints its pass timings. Before scripts/install.sh made `libkage.so.1`, a host linked
/// `-lkage` against the cargo output failed to start.
#[test]
fn readmes_link_and_run_commands_build_a_host_that_runs() {
    let folder = kage_tests::scratch_dir("readme-host");
    std::fs::write(folder.join("host.c"), kage_tests::readme_block("## C ABI", "c")).unwrap();
    let commands = kage_tests::readme_block("### Building a host", "sh");
    // The libraries this test's cargo build made: `<target>/release`.
    let target = library("libkage.so").parent().and_then(Path::parent).expect("<target>").to_path_buf();
    let output = Command::new("bash")
        .args(["-euo", "pipefail", "-c", &commands])
        .current_dir(&folder)
        .env("KAGE", repo())
        .env("CARGO_TARGET_DIR", &target)
        .output()
        .expect("bash");
    let out = succeeded(&format!("README's commands:\n{commands}"), output);
    let soname = folder.join("kage/lib").join(soname());
    assert!(soname.is_file(), "{} was not installed:\n{out}", soname.display());
    // The example prints one line per pass of the last frame, the Tamura passes among them.
    assert!(out.contains("blur_horizontal ") && out.contains(" ms\n"), "{out}");
}

/// Host memory that runs out (tests/c_host/arrays.c, `out-of-memory`): a scene within Kage's
/// limits built under an address-space limit it does not fit in is KAGE_RESULT_OUT_OF_MEMORY,
/// first for the copy of its positions, then for the normals computed from them; the host
/// lives on. (Infallible allocations aborted it: "memory allocation of 1200000000 bytes
/// failed".)
#[test]
fn c_host_out_of_memory_is_an_error_not_an_abort() {
    let out = succeeded("arrays host", Command::new(&hosts().arrays).arg("out-of-memory").output().unwrap());
    println!("{out}");
    assert!(out.ends_with("ok\n"), "{out}");
}

/// Threads and stale handles (tests/c_host/threads.c): one renderer called from four threads,
/// a renderer per thread on one context, a destroy racing a render, destroyed handles reused:
/// every call OK, BUSY or INVALID_HANDLE as the case is, validation on, no crash.
#[test]
fn c_host_threads_and_stale_handles() {
    let out = succeeded("threads host", Command::new(&hosts().threads).output().unwrap());
    println!("{out}");
    assert!(out.contains("stale handles: refused") && out.ends_with("ok\n"), "{out}");
}

/// Memcheck: no invalid read or write, no definite leak. Lavapipe compiles every shader with
/// LLVM, which under valgrind takes most of the time, so these runs are small (2 frames at 16²,
/// unshadowed, validation off) and the two hosts run side by side.
#[test]
fn c_hosts_are_clean_under_valgrind() {
    let hosts = hosts();
    let suppressions = repo().join("tests/c_host/valgrind.supp");
    let memcheck = |host: &Path, args: &[&str]| {
        let mut valgrind = Command::new("valgrind");
        valgrind
            .args([
                "--error-exitcode=99",
                "--leak-check=full",
                "--show-leak-kinds=definite,possible",
                "--errors-for-leak-kinds=definite,possible",
                "--num-callers=40",
            ])
            .arg(format!("--suppressions={}", suppressions.display()))
            .arg(host)
            .args(args);
        let start = Instant::now();
        let output = valgrind.output().expect("valgrind (Debian: valgrind; scripts/deps.sh installs it)");
        (output, start.elapsed())
    };
    let (arrays, vulkan) = std::thread::scope(|s| {
        let arrays = s.spawn(|| memcheck(&hosts.arrays, &["2", "16", "0", "0"]));
        let vulkan = s.spawn(|| memcheck(&hosts.vulkan, &["2", "16", "0", "0"]));
        (arrays.join().unwrap(), vulkan.join().unwrap())
    });
    let (canary, _) = memcheck(&hosts.arrays, &["forget-a-scene"]);
    let report = String::from_utf8_lossy(&canary.stderr);
    assert!(
        canary.status.code() == Some(99) && report.contains("kage_scene_create"),
        "memcheck did not report the canary's forgotten scene ({}):\n{report}",
        canary.status
    );
    for (name, (output, took)) in [("arrays", arrays), ("vulkan", vulkan)] {
        eprintln!("valgrind {name} host: {:.1} s", took.as_secs_f64());
        succeeded(&format!("valgrind of the {name} host"), output);
    }
}
