//! `docs/scene-format.md` stays true to the parser: every scene example in
//! it loads and renders, and every statement the parser knows has a row in
//! its table of statements.
//!
//! The doc's scene examples are its ```-fenced blocks (other code there is
//! indented), so a new example is checked without touching this file.

use host_sim::{load_bytes, new_scene, render, RenderOptions};

fn doc() -> String {
    let path = concat!(env!("CARGO_MANIFEST_DIR"), "/../docs/scene-format.md");
    std::fs::read_to_string(path).unwrap_or_else(|e| panic!("{path}: {e}"))
}

/// The text of every ```-fenced block, in order.
fn fenced_blocks(text: &str) -> Vec<String> {
    let mut blocks = Vec::new();
    let mut current: Option<String> = None;
    for line in text.lines() {
        if line.starts_with("```") {
            match current.take() {
                Some(block) => blocks.push(block),
                None => current = Some(String::new()),
            }
        } else if let Some(block) = &mut current {
            block.push_str(line);
            block.push('\n');
        }
    }
    assert!(current.is_none(), "an unclosed ``` block in docs/scene-format.md");
    blocks
}

#[test]
fn every_example_loads_and_shows_something() {
    let examples = fenced_blocks(&doc());
    assert!(examples.len() >= 2, "found {} examples", examples.len());
    for (i, text) in examples.iter().enumerate() {
        let mut scene = new_scene();
        if let Err(e) = load_bytes(&format!("example {}", i + 1), text.as_bytes(), &mut scene) {
            panic!("example {} of docs/scene-format.md does not load:\n{e}\n{text}", i + 1);
        }
        let options = RenderOptions { size: Some((16, 12)), ..RenderOptions::default() };
        let image = render(&mut scene, &options).expect("the camera is valid").image;
        // A lit object fills the middle of each example: not all one colour.
        let corner = image.pixel(0, 0);
        assert!(image.data.chunks(3).any(|p| p != corner), "example {} renders a blank image", i + 1);
    }
}

#[test]
fn every_statement_has_a_row() {
    // The unknown-keyword message lists every statement the parser knows
    // ("… expected a statement (VIEWPOINT, ORIGIN, …, FRAMES or MOVE)"):
    // its upper-case words, the unknown one aside.
    let mut scene = new_scene();
    let message = match load_bytes("s", b"xyzzy", &mut scene) {
        Err(e) => e.to_string(),
        Ok(_) => panic!("an unknown keyword was accepted"),
    };
    let keywords: Vec<&str> = message
        .split(|c: char| !c.is_ascii_alphabetic())
        .filter(|w| w.len() > 1 && w.bytes().all(|c| c.is_ascii_uppercase()))
        .collect();
    assert!(keywords.len() >= 19, "{message}");
    let doc = doc();
    let counted = format!("**Keywords** are the {} statement names", keywords.len());
    assert!(doc.contains(&counted), "docs/scene-format.md does not say: {counted}");
    for keyword in keywords {
        assert!(doc.contains(&format!("\n| `{keyword}` |")), "docs/scene-format.md has no statement row for {keyword}");
    }
}
