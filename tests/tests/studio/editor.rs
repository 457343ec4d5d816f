//! The page's tools and editor: every tool places its object, selections move
//! and delete, the editor highlights the core's keywords, marks errors and
//! keeps one history.

use super::*;

#[test]
fn every_tool_places_its_object_and_selections_move_and_delete() {
    let dir = tempfile::tempdir().expect("a directory");
    let scene_path = dir.path().join("tools.txt");
    std::fs::write(&scene_path, START).expect("scene written");
    let studio = Studio::start(Some(&scene_path));
    let browser = Browser::start((1500, 900));
    browser.goto(&studio.url);
    browser.wait_for("document.body.dataset.ready === 'true'");

    // Keys 1–8 choose the tools; the sized ones take a point and a size.
    for (key, keyword) in [("2", "BOX 1 "), ("3", "SUPERQUADRIC 1 4 ")] {
        press(&browser, key);
        browser.drag("#wire", (-60, 60), (-60, 40));
        browser.drag("#wire", (0, 0), (20, 0));
        assert!(scene_text(&browser).contains(keyword), "{keyword} placed:\n{}", scene_text(&browser));
    }
    press(&browser, "4");
    for (x, y) in [(-40, 80), (40, 80), (0, 40)] {
        browser.drag("#wire", (x, y), (x, y - 10));
    }
    assert!(scene_text(&browser).contains("TRIANGLE 1 "));
    press(&browser, "5");
    browser.drag("#wire", (-30, 100), (-30, 90));
    browser.drag("#wire", (30, 130), (30, 130));
    assert!(scene_text(&browser).contains("RECTANGLE 1 "));
    press(&browser, "6");
    for (field, value) in [("order", 2), ("rows", 2), ("cols", 2), ("samples", 4)] {
        browser.run(&format!(
            "const i = document.querySelector('#panel input[data-field={field}]');
             i.value = '{value}'; i.dispatchEvent(new Event('change')); return true;"
        ));
    }
    for (x, y) in [(60, 60), (100, 60), (60, 100), (100, 100)] {
        browser.drag("#wire", (x, y), (x, y - 5));
    }
    assert!(scene_text(&browser).contains("BSPLINE 1 2 2 2 4 4"), "{}", scene_text(&browser));
    press(&browser, "8");
    browser.drag("#wire", (-100, 0), (-100, -40));
    assert_eq!(scene_text(&browser).matches("LIGHT ").count(), 2);
    press(&browser, "7");
    browser.drag("#wire", (0, 150), (0, 120));
    assert!(!scene_text(&browser).contains("VIEWPOINT 0 4 12"), "the eye moved");
    assert_eq!(scene_text(&browser).matches("VIEWPOINT").count(), 1);
    // Everything placed is a valid scene, and the page renders it as
    // host-sim does.
    assert!(browser.run("return document.querySelectorAll('#errors li').length;") == 0, "{}", scene_text(&browser));
    render_and_wait(&browser);
    let text = scene_text(&browser);
    assert_same("placed objects", browser.canvas_rgb("image"), &host_render(&text, None).image);

    // Select the box by its centre, drag it along the x–z plane, delete it.
    press(&browser, "s");
    let centre = browser.run(
        "const s = studio.model.find((s) => s.keyword === 'BOX');
         const q = studio.project(s.args.slice(1, 4)); const c = document.getElementById('wire');
         return [Math.round(q[0] - c.width / 2), Math.round(q[1] - c.height / 2)];",
    );
    let (x, y) = (centre[0].as_i64().unwrap(), centre[1].as_i64().unwrap());
    let before: String = text.lines().find(|l| l.starts_with("BOX")).unwrap().into();
    browser.drag("#wire", (x, y), (x + 30, y + 10));
    let after: String = scene_text(&browser).lines().find(|l| l.starts_with("BOX")).unwrap().into();
    assert_ne!(before, after, "the box moved");
    assert_eq!(before.split(' ').nth(5), after.split(' ').nth(5), "sizes kept");
    // The panel edits the selection's numbers.
    browser.run(
        "const i = document.querySelector('#panel input[data-field=\"half x\"]');
         i.value = '0.75'; i.dispatchEvent(new Event('change')); return true;",
    );
    assert!(scene_text(&browser).lines().any(|l| l.starts_with("BOX") && l.split(' ').nth(5) == Some("0.75")));
    press(&browser, "\u{E017}"); // Delete
    assert!(!scene_text(&browser).contains("BOX"), "deleted");
    // Undo (Ctrl+Z) brings it back.
    press(&browser, "\u{E009}z\u{E009}");
    assert!(scene_text(&browser).contains("BOX"), "undone");

    // An image file loads into the display; Clear empties it; help opens.
    let image = octrace_images::formats::Image::Rgb(host_render(&text, Some((20, 10))).image);
    let file = dir.path().join("picture.tga");
    let mut bytes = Vec::new();
    octrace_images::formats::write(&image, octrace_images::formats::Format::Tga, &mut bytes).expect("encoded");
    std::fs::write(&file, bytes).expect("written");
    browser.type_into("#load-image", &file.display().to_string());
    browser.wait_for("document.getElementById('image').dataset.state === 'loaded'");
    assert_same("loaded Targa", browser.canvas_rgb("image"), &image.to_rgb());
    browser.click("#clear");
    assert_eq!(browser.run("return document.getElementById('image').dataset.state;"), "clear");
    press(&browser, "\u{E031}"); // F1
    assert_eq!(browser.run("return document.getElementById('help').open;"), true);
}

/// The editor as people expect one: line numbers, long lines whole
/// (scrolled, never wrapped), the format's keywords highlighted — the
/// core's list (host-sim makes the page's keywords.js from it), every
/// keyword and nothing else — each error marked at its line and column, one
/// undo history for typing and the tools' edits, the page's keys in it,
/// and nothing the page's Content-Security-Policy refuses.
#[test]
fn the_editor_highlights_the_cores_keywords_marks_errors_and_keeps_one_history() {
    let studio = Studio::start(None);
    let browser = Browser::start((1500, 900));
    browser.goto(&studio.url);
    browser.wait_for("document.body.dataset.ready === 'true'");

    // Every keyword of the core, in either ASCII case, beside words that
    // are none: in a comment, quoted, plural, with a non-ASCII letter that
    // upper-cases to S.
    let keywords: Vec<&str> = octrace_core::parse::statement_arities().map(|(keyword, _)| keyword).collect();
    let mut text = String::from("/* SPHERE */ \"BOX\" SPHERES \u{17f}PHERE 1.5e3 -.5 1.2.3 // LIGHT\n");
    for (i, keyword) in keywords.iter().enumerate() {
        text += &if i % 2 == 0 { keyword.to_ascii_lowercase() } else { keyword.to_string() };
        text += "\n";
    }
    set_text(&browser, &text);
    let highlighted: Vec<String> =
        editor_texts(&browser, ".tok-keyword").iter().map(|k| k.to_ascii_uppercase()).collect();
    assert_eq!(highlighted, keywords);
    assert_eq!(editor_texts(&browser, ".tok-comment"), ["/* SPHERE */", "// LIGHT"]);
    assert_eq!(editor_texts(&browser, ".tok-string"), ["\"BOX\""]);
    assert_eq!(editor_texts(&browser, ".tok-number"), ["1.5e3", "-.5"]);
    // Line numbers, one a line.
    let numbers = editor_texts(&browser, ".cm-lineNumbers .cm-gutterElement");
    for line in 1..=keywords.len() + 1 {
        assert!(numbers.contains(&line.to_string()), "line {line} is numbered: {numbers:?}");
    }
    // A long line stays one line: as high as a short one, scrolled sideways.
    set_text(&browser, &format!("RDEPTH 2\nBACKGROUND {}\n", "0.5 ".repeat(120)));
    let lines = in_editor(
        &browser,
        "const lines = [...root.querySelectorAll('.cm-line')].map((l) => l.getBoundingClientRect().height);
         const scroller = root.querySelector('.cm-scroller');
         return [lines[0], lines[1], scroller.scrollWidth > scroller.clientWidth];",
    );
    assert_eq!((&lines[0], &lines[2]), (&lines[1], &true.into()), "no soft wrapping: {lines}");

    // Each error marked where the core says it is, a MOVE's too, and listed.
    let text = "VIEWPOINT 0 0 5\nSPHERE 1 x 0 0 0\nFRAMES 3\nLIGHT 1 0 0 0 MOVE 0 1 1 1 MOVE 1 2 2 2\n\
                LIGHT 1 0 0 0 MOVE 0 1 1 1  1 q 0 0\n";
    set_text(&browser, text);
    let listed = browser
        .run("return [...document.querySelectorAll('#errors li')].map((li) => [li.dataset.line, li.dataset.column]);");
    let listed: Vec<(String, String)> = serde_json::from_value(listed).expect("the errors");
    let at: Vec<(usize, usize)> = listed.iter().map(|(l, c)| (l.parse().unwrap(), c.parse().unwrap())).collect();
    assert_eq!(at, [(2, 10), (4, 28), (5, 31)], "{listed:?}");
    let words: Vec<String> = at
        .iter()
        .map(|&(line, column)| {
            let line = text.lines().nth(line - 1).expect("a line");
            line.chars().skip(column - 1).take_while(|c| !c.is_whitespace()).collect()
        })
        .collect();
    assert_eq!(words, ["x", "MOVE", "q"]);
    let marked = in_editor(
        &browser,
        "const lines = [...root.querySelectorAll('.cm-line')];
         return [...root.querySelectorAll('.cm-lintRange-error')].map((e) => [lines.indexOf(e.closest('.cm-line')) + 1, e.textContent]);",
    );
    assert_eq!(marked, serde_json::json!([[2, "x"], [4, "MOVE"], [5, "q"]]));
    assert_eq!(editor_texts(&browser, ".cm-gutter-lint .cm-lint-marker-error").len(), 3, "a mark in the gutter a line");

    // One history: typing, then a tool's edit (the panel's background),
    // undone in turn by Ctrl+Z outside the editor, and redone by Ctrl+Y.
    set_text(&browser, START);
    let content = browser.run("return studio.editor.view.contentDOM;");
    browser.type_into_element(&content, "RDEPTH 2");
    let typed = scene_text(&browser);
    assert!(typed.starts_with(START) && typed.contains("RDEPTH 2"), "{typed}");
    press(&browser, "\u{E00C}"); // Escape: the scene's panel
                                 // Its lights are numbered among the lights, not among the statements.
    let lights = browser.run(
        "return [...document.querySelectorAll('#panel input')].map((i) => i.dataset.field)
           .filter((f) => f.startsWith('light'));",
    );
    assert_eq!(lights, serde_json::json!(["light 1 brightness"]));
    browser.run(
        "const i = document.querySelector('#panel input[data-field=\"background r\"]');
         i.value = '0.5'; i.dispatchEvent(new Event('change')); return true;",
    );
    let edited = scene_text(&browser);
    assert!(edited.contains("BACKGROUND 0.5 0.1 0.15"), "{edited}");
    press(&browser, "\u{E009}z\u{E009}");
    assert_eq!(scene_text(&browser), typed, "the panel's edit undone");
    press(&browser, "\u{E009}z\u{E009}");
    assert_eq!(scene_text(&browser), START, "the typing undone");
    press(&browser, "\u{E009}y\u{E009}");
    assert_eq!(scene_text(&browser), typed, "the typing redone");
    browser.click("#redo");
    assert_eq!(scene_text(&browser), edited, "the panel's edit redone");

    // Ctrl+Enter in the editor renders, and adds no line.
    browser.run("studio.editor.view.focus(); document.getElementById('image').dataset.state = 'stale'; return true;");
    browser.keys("\u{E009}\u{E007}\u{E009}");
    browser.wait_for("document.getElementById('image').dataset.state === 'done'");
    assert_eq!(scene_text(&browser), edited);
    assert_eq!(page_log(&browser), serde_json::json!([]), "nothing refused, no script error");
}
