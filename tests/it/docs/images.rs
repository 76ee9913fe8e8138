//! Every picture the README and `docs/` show is in the repository: a reference to a missing
//! file (one left untracked, or ignored by `.gitignore`) fails here on a fresh clone.

use std::path::{Path, PathBuf};

/// The local targets of `![alt](target)` in a Markdown text.
fn images(markdown: &str) -> Vec<String> {
    let mut found = Vec::new();
    let mut rest = markdown;
    while let Some(i) = rest.find("![") {
        rest = &rest[i + 2..];
        let Some(close) = rest.find("](") else { break };
        let after = &rest[close + 2..];
        let Some(end) = after.find(')') else { break };
        let target = after[..end].split_whitespace().next().unwrap_or("");
        if !target.contains("://") {
            found.push(target.to_string());
        }
        rest = &after[end..];
    }
    found
}

#[test]
fn every_image_the_docs_show_exists() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let mut pages: Vec<PathBuf> = vec![root.join("README.md")];
    for entry in std::fs::read_dir(root.join("docs")).unwrap() {
        let p = entry.unwrap().path();
        if p.extension().is_some_and(|e| e == "md") {
            pages.push(p);
        }
    }
    let mut shown = 0;
    let mut missing = Vec::new();
    for page in &pages {
        let text = std::fs::read_to_string(page).unwrap();
        for target in images(&text) {
            shown += 1;
            let file = page.parent().unwrap().join(&target);
            if !file.is_file() {
                missing.push(format!("{} shows {target}", page.display()));
            }
        }
    }
    assert!(shown >= 3, "the README and docs show pictures: {shown}");
    assert!(
        missing.is_empty(),
        "missing pictures:\n{}",
        missing.join("\n")
    );
}

#[test]
fn image_links_are_read_from_markdown() {
    let md = "text ![a chart](docs/a.png) and ![b](b.gif \"title\") and ![c](https://x/c.png)";
    assert_eq!(images(md), vec!["docs/a.png", "b.gif"]);
}
