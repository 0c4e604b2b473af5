//! Bad input, one fixture per mistake and section: every file in
//! tests/data/bad/ begins with `# error: LINE: message` (or `# error:
//! message` for the file as a whole) and must be refused with exactly that
//! `file:line: message`, never a panic.

use std::path::Path;

use mote_md::rigid::scene::{is_rigid_scene, RigidScene};
use mote_md::scene::Scene;

/// The error a fixture expects, as `file:line: message` for `file`.
fn expected(file: &str, text: &str) -> String {
    let header = text
        .lines()
        .next()
        .and_then(|l| l.strip_prefix("# error: "))
        .unwrap_or_else(|| panic!("{file}: the first line must be `# error: ...`"));
    match header.split_once(": ") {
        Some((line, message)) if line.bytes().all(|b| b.is_ascii_digit()) => {
            format!("{file}:{line}: {message}")
        }
        _ => format!("{file}: {header}"),
    }
}

#[test]
fn every_bad_scene_is_refused_with_its_file_line_and_message() {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/data/bad");
    let mut paths: Vec<_> = std::fs::read_dir(&dir)
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| p.extension().is_some_and(|e| e == "toml"))
        .collect();
    paths.sort();
    assert!(paths.len() >= 20, "fixtures missing in {}", dir.display());
    let mut failures = Vec::new();
    for path in &paths {
        let file = format!("bad/{}", path.file_name().unwrap().to_string_lossy());
        let text = std::fs::read_to_string(path).unwrap();
        let want = expected(&file, &text);
        // One scene file for both kinds: a [rigid] table makes it rigid.
        let built = if is_rigid_scene(&text) {
            RigidScene::parse(&text, &file).and_then(|s| s.build(&text, &file, None).map(|_| ()))
        } else {
            Scene::parse(&text, &file).and_then(|s| s.build(&text, &file, 1).map(|_| ()))
        };
        let got = match built {
            Ok(()) => "accepted".to_string(),
            Err(e) => e.to_string(),
        };
        if got != want {
            failures.push(format!("  want {want}\n   got {got}"));
        }
    }
    assert!(failures.is_empty(), "\n{}", failures.join("\n"));
}

/// A request larger than the machine is refused before anything is
/// allocated, with both numbers (the available memory is the machine's, so
/// only the request's part is pinned).
#[test]
fn a_scene_too_large_for_the_machine_is_refused_before_allocating() {
    let text =
        "units = \"lj\"\n[run]\ndt = 0.001\n[[fcc]]\ncells = [2000, 2000, 2000]\ndensity = 0.8\n";
    let e = Scene::parse(text, "huge.toml")
        .and_then(|s| s.build(text, "huge.toml", 1))
        .err()
        .expect("a 3.2e10-particle crystal must be refused")
        .to_string();
    assert!(
        e.starts_with("huge.toml:4: the scene makes 32000000000 particles (32000000000 from this [[fcc]]), which needs at least 14.4 TB, and this machine has "),
        "{e}"
    );
    assert!(e.ends_with(" available"), "{e}");
}
