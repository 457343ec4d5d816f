//! The documentation a newcomer reads holds together: the README stays
//! short enough to read in five minutes, and every relative link in it and
//! in `docs/` and the board templates' READMEs leads to a file that exists
//! and, where it names a heading, to that heading.

use std::collections::BTreeSet;
use std::path::{Path, PathBuf};

/// The most lines the README may have.
const README_LINES: usize = 300;

/// The Markdown files checked: the README, BENCHMARKS.md, docs/*.md and
/// every README below the repository's own folders.
fn documents() -> Vec<PathBuf> {
    let repo = octrace_tests::repo();
    let mut found = vec![repo.join("README.md"), repo.join("BENCHMARKS.md")];
    let mut stack = vec![repo.join("docs"), repo.join("examples"), repo.join("emulator"), repo.join("fuzz")];
    while let Some(dir) = stack.pop() {
        for entry in std::fs::read_dir(&dir).unwrap_or_else(|e| panic!("{}: {e}", dir.display())) {
            let path = entry.expect("an entry").path();
            let name = path.file_name().and_then(|n| n.to_str()).unwrap_or_default();
            if path.is_dir() && !matches!(name, "node_modules" | "target") {
                stack.push(path);
            } else if path.extension().is_some_and(|e| e == "md") {
                found.push(path);
            }
        }
    }
    found.sort();
    found
}

/// The targets of the Markdown links `[text](target)` in `text`, outside
/// code blocks and code spans.
fn links(text: &str) -> Vec<String> {
    let mut found = Vec::new();
    let mut fenced = false;
    for line in text.lines() {
        if line.trim_start().starts_with("```") {
            fenced = !fenced;
            continue;
        }
        if fenced || line.starts_with("    ") {
            continue;
        }
        // Code spans hold no links.
        let prose: String = line.split('`').step_by(2).collect::<Vec<_>>().join("");
        let mut rest = prose.as_str();
        while let Some(at) = rest.find("](") {
            let after = &rest[at + 2..];
            let Some(end) = after.find(')') else { break };
            found.push(after[..end].to_string());
            rest = &after[end..];
        }
    }
    found
}

/// The anchors GitHub gives the headings of a Markdown text: lower case,
/// each space a hyphen, punctuation but hyphens and underscores dropped, a
/// repeated one numbered.
fn anchors(text: &str) -> BTreeSet<String> {
    let mut seen = BTreeSet::new();
    let mut fenced = false;
    for line in text.lines() {
        if line.trim_start().starts_with("```") {
            fenced = !fenced;
        }
        if fenced || !line.starts_with('#') {
            continue;
        }
        let heading = line.trim_start_matches('#').trim();
        let slug: String = heading
            .to_lowercase()
            .chars()
            .filter(|c| c.is_alphanumeric() || matches!(c, ' ' | '-' | '_'))
            .map(|c| if c == ' ' { '-' } else { c })
            .collect();
        let mut anchor = slug.clone();
        let mut n = 0;
        while !seen.insert(anchor.clone()) {
            n += 1;
            anchor = format!("{slug}-{n}");
        }
    }
    seen
}

/// Every broken link of the document at `path`.
fn broken_links(path: &Path) -> Vec<String> {
    let text = std::fs::read_to_string(path).expect("a document");
    let mut broken = Vec::new();
    for link in links(&text) {
        if link.contains("://") || link.starts_with("mailto:") {
            continue;
        }
        let (file, anchor) = link.split_once('#').map_or((link.as_str(), None), |(f, a)| (f, Some(a)));
        let target = if file.is_empty() { path.to_path_buf() } else { path.parent().expect("a folder").join(file) };
        if !target.exists() {
            broken.push(format!("{}: {link}: no such file", path.display()));
            continue;
        }
        if let Some(anchor) = anchor.filter(|_| target.extension().is_some_and(|e| e == "md")) {
            let headings = anchors(&std::fs::read_to_string(&target).expect("a document"));
            if !headings.contains(anchor) {
                broken.push(format!("{}: {link}: no such heading", path.display()));
            }
        }
    }
    broken
}

#[test]
fn the_readme_is_short() {
    let readme = std::fs::read_to_string(octrace_tests::repo().join("README.md")).expect("README.md");
    let lines = readme.lines().count();
    assert!(lines <= README_LINES, "README.md has {lines} lines, at most {README_LINES}: move the depth to docs/");
}

#[test]
fn every_relative_link_leads_to_its_file_and_heading() {
    let documents = documents();
    assert!(documents.len() > 10, "only {} documents found", documents.len());
    let broken: Vec<String> = documents.iter().flat_map(|d| broken_links(d)).collect();
    assert!(broken.is_empty(), "{} broken links:\n{}", broken.len(), broken.join("\n"));
}

#[test]
fn the_check_sees_a_missing_file_and_a_missing_heading() {
    let dir = tempfile::tempdir().expect("a folder");
    let page = dir.path().join("page.md");
    std::fs::write(dir.path().join("other.md"), "# Other\n\n## Its part, `code` and all\n").expect("written");
    std::fs::write(
        &page,
        "# Page\n\n[ok](other.md#its-part-code-and-all) [here](#page) [gone](missing.md) \
         [no](other.md#nowhere) `[not a link](x.md)`\n\n    [indented](code.md)\n",
    )
    .expect("written");
    let broken = broken_links(&page);
    assert_eq!(broken.len(), 2, "{broken:?}");
    assert!(
        broken[0].ends_with("missing.md: no such file") && broken[1].ends_with("other.md#nowhere: no such heading")
    );
}
