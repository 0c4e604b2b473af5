//! Bad input, one fixture per mistake and section: every file in
//! tests/data/bad/ begins with `# error: LINE: message` (or `# error:
//! message` for the file as a whole) and must be refused with exactly that
//! `file:line: message`, never a panic.

use std::path::Path;

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
        let got = match Scene::parse(&text, &file).and_then(|s| s.build(&text, &file, 1)) {
            Ok(_) => "accepted".to_string(),
            Err(e) => e.to_string(),
        };
        if got != want {
            failures.push(format!("  want {want}\n   got {got}"));
        }
    }
    assert!(failures.is_empty(), "\n{}", failures.join("\n"));
}
