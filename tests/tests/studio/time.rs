//! An animation in the studio: the time slider and play show host-sim's frames,
//! each frame re-tracing only what moved.

use super::*;

/// The share of the render's pixels the page says it traced for its frame.
fn traced_share(browser: &Browser) -> f64 {
    let status = browser.run("return document.getElementById('status').textContent;");
    let status = status.as_str().expect("a status");
    let share = status.split(", ").nth(1).and_then(|s| s.split(' ').next()).and_then(|n| n.parse().ok());
    share.unwrap_or_else(|| panic!("a share of pixels traced in {status:?}"))
}

/// Plays the page's animation for 30 frames, then pauses; returns the frame
/// it stopped at, once shown. Prints how fast `what` played.
fn play_and_pause(browser: &Browser, what: &str) -> u32 {
    let start = browser.run("return studio.frame;").as_u64().expect("a frame");
    browser.click("#play");
    browser.wait_for("studio.played && studio.played.length >= 30");
    browser.click("#play");
    let shown =
        format!("{FRAME_PICTURES}.every((id) => document.getElementById(id).dataset.frame === String(studio.frame))");
    browser.wait_for(&format!("!studio.playing && {shown}"));
    let frame = browser.run("return studio.frame;").as_u64().expect("a frame");
    let played = browser.run("return studio.played;");
    let played = played.as_array().expect("the frames played");
    let frames: Vec<u64> = played.iter().map(|p| p["frame"].as_u64().expect("a frame")).collect();
    let in_turn: Vec<u64> = (1..=frames.len() as u64).map(|i| (start + i) % 48).collect();
    assert_eq!(frames, in_turn, "every frame in turn");
    assert_eq!(frame, in_turn[in_turn.len() - 1], "paused at the last frame played");
    // The first frame is traced whole (with the tracker's search of the
    // loop); the others re-trace what moved.
    let mut ms: Vec<f64> = played.iter().skip(1).map(|p| p["ms"].as_f64().expect("ms")).collect();
    let mut shares: Vec<f64> = played.iter().skip(1).map(|p| p["share"].as_f64().expect("a share")).collect();
    ms.sort_by(f64::total_cmp);
    shares.sort_by(f64::total_cmp);
    let shown = |i: usize| played[i]["at"].as_f64().expect("a time");
    let rate = 1000.0 * (played.len() - 2) as f64 / (shown(played.len() - 1) - shown(1));
    println!(
        "anim_fig5_1 played, {what}: {} frames at {rate:.1} a second; the first in {:.1} ms, the others each in \
         {:.1} ms (median; slowest {:.1} ms), {:.1} % of the draft's pixels traced (median)",
        played.len(),
        played[0]["ms"].as_f64().expect("ms"),
        ms[ms.len() / 2],
        ms[ms.len() - 1],
        shares[shares.len() / 2]
    );
    frame as u32
}

/// An animation in the studio: the time controls show for a scene with
/// FRAMES and not for a still; the frame of the slider is what the render
/// and the draft show, host-sim's `--frame K` picture bit for bit, reached
/// forward (re-tracing only what moved), by a jump, backwards or round the
/// loop; the wireframe and the tools see the objects where they are at that
/// frame; play goes through the frames in turn, and where it stops is
/// host-sim's frame too; an error of one frame only (the eye moved onto the
/// point looked at) is marked at its MOVE when that frame is shown.
#[test]
fn the_time_slider_and_play_show_host_sims_frames() {
    let dir = tempfile::tempdir().expect("a directory");
    let scene = dir.path().join("anim_fig5_1.txt");
    std::fs::copy(scene_path("anim_fig5_1"), &scene).expect("copied");
    let studio = Studio::start(Some(&scene));
    let browser = Browser::start((1500, 900));
    browser.goto(&studio.url);
    browser.wait_for("document.body.dataset.ready === 'true'");
    let controls =
        browser.run("return [document.getElementById('time').hidden, document.getElementById('frame').max];");
    assert_eq!(controls, serde_json::json!([false, "47"]));

    // Play the draft alone, then pause: the frames went by in turn, and
    // the draft shows host-sim's frame.
    browser.wait_for("document.getElementById('draft').dataset.state === 'done'");
    let frame = play_and_pause(&browser, "the draft (160x120)");
    let draft = host_frame(&scene, frame, Some("160x120"));
    assert_same(&format!("draft of frame {frame}, played to"), browser.canvas_rgb("draft"), &draft);
    slide_to(&browser, 0);
    // What the page's module takes for a draft of each frame: traced whole,
    // and by its player, twice round the loop (loading and indexing the
    // frame included; printed for BENCHMARKS.md).
    let timed = browser.run(
        "const octrace = studio.octrace, text = studio.editor.text(), whole = [], played = [];
         const time = (k, trace) => { const t = performance.now(); octrace.load(text, k); octrace.prepare(0, 160, 120);
                                      trace(); return performance.now() - t; };
         for (let k = 0; k < 48; k++) whole.push(time(k, () => octrace.render(0, 0, 160, 120)));
         for (let k = 0; k < 96; k++) played.push(time(k % 48, () => octrace.traceFrame()));
         const median = (all) => all.slice().sort((a, b) => a - b)[all.length >> 1];
         return [median(whole), played[0], median(played.slice(1))];",
    );
    println!(
        "anim_fig5_1's draft (160x120) in the page's module: a frame traced whole in {:.1} ms (median), \
         by the player the first in {:.1} ms, the others in {:.1} ms (median)",
        timed[0].as_f64().expect("ms"),
        timed[1].as_f64().expect("ms"),
        timed[2].as_f64().expect("ms")
    );

    // Frame 0, rendered as any scene is (parallel tiles), and its draft.
    render_and_wait(&browser);
    assert_same("frame 0", browser.canvas_rgb("image"), &host_frame(&scene, 0, None));
    browser.wait_for("document.getElementById('draft').dataset.state === 'done'");
    assert_same("draft of frame 0", browser.canvas_rgb("draft"), &host_frame(&scene, 0, Some("160x120")));
    // Then frames forward (re-tracing a small share), a jump, backwards,
    // and round the loop from the last frame to the first.
    for (frame, forward) in [(1, false), (2, true), (30, false), (29, false), (47, false), (0, true)] {
        slide_to(&browser, frame);
        let share = traced_share(&browser);
        assert!(!forward || share < 50.0, "frame {frame}: {share} % of the pixels traced");
        assert_same(&format!("frame {frame}"), browser.canvas_rgb("image"), &host_frame(&scene, frame, None));
        let draft = host_frame(&scene, frame, Some("160x120"));
        assert_same(&format!("draft of frame {frame}"), browser.canvas_rgb("draft"), &draft);
    }

    // Play with the render shown, then pause: the frame shown is host-sim's.
    let frame = play_and_pause(&browser, "the render (240x180) and the draft (160x120)");
    assert_same(&format!("frame {frame}, played to"), browser.canvas_rgb("image"), &host_frame(&scene, frame, None));
    let draft = host_frame(&scene, frame, Some("160x120"));
    assert_same(&format!("draft of frame {frame}, played to"), browser.canvas_rgb("draft"), &draft);
    screenshot(&browser, "studio");

    // A render asked for while playing stops the player and stays: the
    // frame shown then, whole, not replaced by a frame the player was
    // still tracing.
    browser.click("#play");
    browser.wait_for("studio.played && studio.played.length >= 3");
    render_and_wait(&browser);
    let frame = browser.run("return studio.frame;").as_u64().expect("a frame") as u32;
    // Time for a frame the player traced to come, were it still shown.
    std::thread::sleep(std::time::Duration::from_millis(500));
    assert_eq!(browser.run("return [studio.playing, studio.frame];"), serde_json::json!([false, frame]));
    let image = browser.canvas_rgb("image");
    assert_same(&format!("frame {frame}, rendered while playing"), image, &host_frame(&scene, frame, None));

    // The wireframe shows the red sphere where frame 10 has it (its MOVE's
    // second key: 0.3 left of and 3 behind where it is written), and the
    // select tool picks it there.
    let wire_at = |frame: u32| {
        slide_to(&browser, frame);
        browser.run("return document.getElementById('wire').toDataURL();")
    };
    let (at_0, at_10) = (wire_at(0), wire_at(10));
    assert!(at_0 != at_10, "the wireframe follows the frame");
    assert!(wire_at(0) == at_0, "the wireframe at frame 0 again");
    wire_at(10);
    press(&browser, "s");
    let there = browser.run(
        "const q = studio.project([-2.6 - 0.3, 0.3, 0.6 - 3.0]); const c = document.getElementById('wire');
         return [Math.round(q[0] - c.width / 2), Math.round(q[1] - c.height / 2)];",
    );
    let (x, y) = (there[0].as_i64().expect("x"), there[1].as_i64().expect("y"));
    browser.drag("#wire", (x, y), (x, y));
    let picked = browser.run("const s = studio.model[studio.selection]; return s && [s.keyword, s.args[1]];");
    assert_eq!(picked, serde_json::json!(["SPHERE", 1.3]), "the red sphere, picked where it is at frame 10");

    // An error at one frame only: the eye moves onto the point looked at
    // at frame 2. Every frame's camera is checked as the text loads, so the
    // page marks it at the MOVE whichever frame is shown (frame 0 here).
    slide_to(&browser, 0);
    set_text(
        &browser,
        "FRAMES 3\nORIGIN 0 0 0\nVIEWPOINT 0 0 5 MOVE 0 0 0 0  2 0 0 -5\nLIGHT 5 3 3 3\n\
         SURFACE 1 .1 .1 .1 .7 .2 .2 0 0 0 1 0 0\nSPHERE 1 1 0 0 -9\n",
    );
    browser.wait_for(
        "[...document.querySelectorAll('#errors li')].some((li) => li.textContent.startsWith('3:17: ') \
         && li.textContent.includes('frame 2'))",
    );
    assert_eq!(editor_texts(&browser, ".cm-lintRange-error"), ["MOVE"]);

    // A still scene hides the controls.
    set_text(&browser, START);
    assert_eq!(browser.run("return document.getElementById('time').hidden;"), true);
    assert_eq!(page_log(&browser), serde_json::json!([]), "nothing refused, no script error");
}
