//! Layers are folders and imports flow down: the kernel names no effect, effects name only
//! the effects below them, tools sit on top, and no two modules of one folder import each
//! other in a circle. Read from the sources, so a new import that runs back up fails here
//! with the file and the path it names.

use std::collections::{BTreeMap, BTreeSet};
use std::path::{Path, PathBuf};

/// The top-level modules from the bottom up; a module may import only from lower layers.
const LAYERS: &[&[&str]] = &[
    &["core"],
    &["particles"],
    &["rigid"],
    &["integrator"],
    &["collision"],
    &["springs"],
    &["joints"],
    &["sleep"],
    &["soft", "cloth", "character"],
    &["plugins", "snapshot"],
    &["bevy"],
    &["tools"],
];

/// A module path (`["collision", "solver", "fused"]`) and the file it is defined in.
struct Module {
    path: Vec<String>,
    file: PathBuf,
}

fn modules(dir: &Path, prefix: &[String], out: &mut Vec<Module>) {
    let mut entries: Vec<_> = std::fs::read_dir(dir)
        .unwrap()
        .map(|e| e.unwrap().path())
        .collect();
    entries.sort();
    for p in entries {
        let name = p.file_stem().unwrap().to_string_lossy().to_string();
        if p.is_dir() {
            if prefix.is_empty() && name == "bin" {
                continue; // binaries are crates of their own
            }
            let mut sub = prefix.to_vec();
            sub.push(name);
            modules(&p, &sub, out);
        } else if p.extension().is_some_and(|e| e == "rs") {
            let mut path = prefix.to_vec();
            if name != "mod" && name != "lib" {
                path.push(name);
            }
            out.push(Module { path, file: p });
        }
    }
}

/// Source without comments, so that doc links and prose do not count as imports.
fn code(text: &str) -> String {
    let mut out = String::with_capacity(text.len());
    let mut rest = text;
    while !rest.is_empty() {
        if rest.starts_with("//") {
            rest = rest.find('\n').map_or("", |i| &rest[i..]);
        } else if rest.starts_with("/*") {
            rest = rest.find("*/").map_or("", |i| &rest[i + 2..]);
        } else {
            let c = rest.chars().next().unwrap();
            out.push(c);
            rest = &rest[c.len_utf8()..];
        }
    }
    out
}

/// Every `crate::a::b`, `super::a` and `self::a` path in `code`, made absolute.
fn references(code: &str, me: &[String]) -> Vec<Vec<String>> {
    let mut found = Vec::new();
    let bytes = code.as_bytes();
    for head in ["crate", "super", "self"] {
        let mut from = 0;
        while let Some(at) = code[from..].find(head).map(|i| i + from) {
            from = at + head.len();
            let before = at.checked_sub(1).map(|i| bytes[i]);
            if before.is_some_and(|b| b.is_ascii_alphanumeric() || b == b'_' || b == b':') {
                continue;
            }
            let mut segments = Vec::new();
            let mut rest = &code[from..];
            while let Some(tail) = rest.strip_prefix("::") {
                let n = tail
                    .find(|c: char| !(c.is_ascii_alphanumeric() || c == '_'))
                    .unwrap_or(tail.len());
                if n == 0 {
                    break;
                }
                segments.push(tail[..n].to_string());
                rest = &tail[n..];
            }
            if segments.is_empty() {
                continue;
            }
            let mut base: Vec<String> = match head {
                "crate" => Vec::new(),
                "self" => me.to_vec(),
                // `super` of a file `a/b.rs` and of a folder `a/b/mod.rs` is `a`.
                _ => me[..me.len().saturating_sub(1)].to_vec(),
            };
            base.extend(segments);
            found.push(base);
        }
    }
    found
}

/// For each folder, the imports between its child modules: (from, to) → where.
type Edges = BTreeMap<Vec<String>, BTreeMap<(String, String), String>>;

fn edges() -> Edges {
    let mut all = Vec::new();
    modules(
        &Path::new(env!("CARGO_MANIFEST_DIR")).join("src"),
        &[],
        &mut all,
    );
    let known: BTreeSet<Vec<String>> = all.iter().map(|m| m.path.clone()).collect();
    let mut edges = Edges::new();
    for m in &all {
        let text = std::fs::read_to_string(&m.file).unwrap();
        for target in references(&code(&text), &m.path) {
            let common = m
                .path
                .iter()
                .zip(&target)
                .take_while(|(a, b)| a == b)
                .count();
            if common >= m.path.len() || common >= target.len() {
                continue; // a module naming itself, its parent or its own children
            }
            let folder = m.path[..common].to_vec();
            let (a, b) = (&m.path[common], &target[common]);
            let child = |n: &String| {
                let mut p = folder.clone();
                p.push(n.clone());
                known.contains(&p)
            };
            if child(a) && child(b) {
                let file = m.file.strip_prefix(env!("CARGO_MANIFEST_DIR")).unwrap();
                edges
                    .entry(folder)
                    .or_default()
                    .entry((a.clone(), b.clone()))
                    .or_insert_with(|| format!("{} names {}", file.display(), target.join("::")));
            }
        }
    }
    edges
}

/// A circle among `edges`, if there is one.
fn circle(edges: &BTreeMap<(String, String), String>) -> Option<Vec<String>> {
    fn visit(
        node: &String,
        edges: &BTreeMap<(String, String), String>,
        path: &mut Vec<String>,
        done: &mut BTreeSet<String>,
    ) -> Option<Vec<String>> {
        if let Some(i) = path.iter().position(|p| p == node) {
            return Some(path[i..].to_vec());
        }
        if done.contains(node) {
            return None;
        }
        path.push(node.clone());
        for (a, b) in edges.keys() {
            if a == node
                && let Some(c) = visit(b, edges, path, done)
            {
                return Some(c);
            }
        }
        path.pop();
        done.insert(node.clone());
        None
    }
    let mut done = BTreeSet::new();
    for (a, _) in edges.keys() {
        if let Some(c) = visit(a, edges, &mut Vec::new(), &mut done) {
            return Some(c);
        }
    }
    None
}

#[test]
fn no_two_modules_of_a_folder_import_each_other_in_a_circle() {
    let edges = edges();
    assert!(
        edges.contains_key(&Vec::new()),
        "the crate root has modules"
    );
    let mut circles = Vec::new();
    for (folder, e) in &edges {
        if let Some(c) = circle(e) {
            let hops: Vec<String> = c
                .iter()
                .zip(c.iter().cycle().skip(1))
                .map(|(a, b)| e[&(a.clone(), b.clone())].clone())
                .collect();
            circles.push(format!("in src/{}: {}", folder.join("/"), hops.join("; ")));
        }
    }
    assert!(
        circles.is_empty(),
        "import circles:\n{}",
        circles.join("\n")
    );
}

#[test]
fn imports_flow_down_the_layers() {
    let layer = |m: &str| LAYERS.iter().position(|l| l.contains(&m));
    let edges = edges();
    let mut wrong = Vec::new();
    for ((a, b), at) in &edges[&Vec::new()] {
        match (layer(a), layer(b)) {
            (Some(la), Some(lb)) if lb < la => {}
            (Some(_), Some(_)) => wrong.push(format!("{a} -> {b}: {at}")),
            _ => wrong.push(format!("{a} or {b} has no layer in LAYERS: {at}")),
        }
    }
    assert!(
        wrong.is_empty(),
        "imports up or across a layer:\n{}",
        wrong.join("\n")
    );
}

#[test]
fn the_check_sees_a_circle_when_there_is_one() {
    let mut e = BTreeMap::new();
    for (a, b) in [("x", "y"), ("y", "z"), ("z", "x"), ("z", "w")] {
        e.insert((a.to_string(), b.to_string()), String::new());
    }
    let c = circle(&e).expect("x -> y -> z -> x");
    assert_eq!(c.len(), 3);
    e.remove(&("z".to_string(), "x".to_string()));
    assert_eq!(circle(&e), None);
    let refs = references(
        "use super::solver::Body; let x = crate::core::time::PhysicsTime::default();",
        &["collision".into(), "narrow_phase".into()],
    );
    assert_eq!(
        refs,
        vec![
            vec!["core", "time", "PhysicsTime", "default"],
            vec!["collision", "solver", "Body"],
        ]
        .into_iter()
        .map(|v| v.into_iter().map(String::from).collect::<Vec<_>>())
        .collect::<Vec<_>>()
    );
}
