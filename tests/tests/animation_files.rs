//! Animated files as others read them (issue 49): every GIF and APNG
//! host-sim writes plays in Chromium (its own decoder, through WebCodecs'
//! `ImageDecoder`, and as an `<img>`) with the right frames, delays and
//! looping, and ffprobe reads the right frame count and rate. The APNG,
//! decoded by the browser, is host-sim's frames bit for bit; the GIF,
//! decoded by the browser, meets issue 49's quality target against
//! `--frame K` (PSNR over RGB, mean over the loop ≥ 45 dB, no frame under
//! 40 dB), also for anim_colours, whose colours change greatly over its
//! loop, and a pixel a frame did not change keeps its colour (no
//! shimmer). Small sizes and few frames: the full-size figures are
//! `octrace-bench animfiles`'s.

use octrace_images::palette::psnr;
use octrace_images::RgbImage;
use octrace_tests::scene_path;
use octrace_tests::webdriver::{base64_decode, Browser};
use serde_json::Value;
use std::path::Path;

/// host-sim's command line as a program (`tests/src/bin/host-sim-cli.rs`).
const HOST_SIM: &str = env!("CARGO_BIN_EXE_host-sim-cli");

fn host_sim(dir: &Path, args: &[&str]) {
    let output = std::process::Command::new(HOST_SIM).args(args).current_dir(dir).output().expect("host-sim-cli runs");
    assert!(output.status.success(), "host-sim {args:?}: {}", String::from_utf8_lossy(&output.stderr));
}

/// The scene `name` of scenes/ at `width` × `height`, written into `dir`:
/// its file's name, its frame count and rate.
fn small(dir: &Path, name: &str, (width, height): (u32, u32)) -> (String, u32, u32) {
    let text = std::fs::read_to_string(scene_path(name)).expect("the scene");
    let mut out = String::new();
    let (mut count, mut rate) = (0, 24);
    for line in text.lines() {
        let words: Vec<&str> = line.split_whitespace().collect();
        match words.first().copied() {
            Some("RASTER") => out.push_str(&format!("RASTER {width} {height}\n")),
            Some("FRAMES") => {
                count = words[1].parse().expect("a count");
                rate = words.get(2).map_or(24, |r| r.parse().expect("a rate"));
                out.push_str(&format!("{line}\n"));
            }
            _ => out.push_str(&format!("{line}\n")),
        }
    }
    let file = format!("{name}.txt");
    std::fs::write(dir.join(&file), out).expect("written");
    (file, count, rate)
}

/// host-sim's frames of `scene` (`--frame K` is each, bit for bit:
/// tests/tests/animation.rs), read back.
fn frames(dir: &Path, scene: &str, count: u32) -> Vec<RgbImage> {
    host_sim(dir, &[scene, "frame%03d.png", "-q"]);
    (0..count)
        .map(|k| {
            let bytes = std::fs::read(dir.join(format!("frame{k:03}.png"))).expect("a frame file");
            octrace_images::formats::read(&bytes).expect("a PNG").to_rgb()
        })
        .collect()
}

/// What the browser made of an animated file.
struct Played {
    frames: Vec<RgbImage>,
    /// Each frame's duration, in microseconds.
    durations: Vec<u64>,
    /// `ImageDecoder`'s repetition count (infinite for a loop forever).
    repetitions: f64,
    /// The `<img>`'s natural width once decoded.
    shown_width: u64,
}

/// `bytes` (of MIME type `mime`) decoded by Chromium: each frame as
/// composed, drawn on a canvas.
fn play(browser: &Browser, bytes: &[u8], mime: &str, (w, h): (u32, u32)) -> Played {
    let script = format!(
        "return (async () => {{
           const bytes = Uint8Array.from(atob('{data}'), c => c.charCodeAt(0));
           const img = new Image();
           img.src = URL.createObjectURL(new Blob([bytes], {{ type: '{mime}' }}));
           await img.decode();
           const decoder = new ImageDecoder({{ data: bytes, type: '{mime}', colorSpaceConversion: 'none' }});
           await decoder.tracks.ready;
           await decoder.completed;
           const track = decoder.tracks.selectedTrack;
           const canvas = new OffscreenCanvas({w}, {h});
           const context = canvas.getContext('2d', {{ willReadFrequently: true }});
           const durations = [];
           let rgb = '';
           for (let i = 0; i < track.frameCount; i++) {{
             const {{ image }} = await decoder.decode({{ frameIndex: i }});
             durations.push(image.duration);
             context.clearRect(0, 0, {w}, {h});
             context.drawImage(image, 0, 0);
             image.close();
             const d = context.getImageData(0, 0, {w}, {h}).data;
             for (let j = 0; j < d.length; j += 4) rgb += String.fromCharCode(d[j], d[j + 1], d[j + 2]);
           }}
           const repetitions = track.repetitionCount === Infinity ? -1 : track.repetitionCount;
           return [img.naturalWidth, repetitions, durations, btoa(rgb)];
         }})();",
        data = base64(bytes)
    );
    let v = browser.run(&script);
    let rgb = base64_decode(v[3].as_str().expect("pixels"));
    let size = 3 * (w * h) as usize;
    Played {
        frames: rgb.chunks(size).map(|d| RgbImage { width: w, height: h, data: d.to_vec() }).collect(),
        durations: v[2].as_array().expect("durations").iter().map(|d| d.as_u64().expect("a duration")).collect(),
        repetitions: match v[1].as_f64().expect("repetitions") {
            r if r < 0.0 => f64::INFINITY,
            r => r,
        },
        shown_width: v[0].as_u64().expect("a width"),
    }
}

fn base64(bytes: &[u8]) -> String {
    const SYMBOLS: &[u8; 64] = b"ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
    let mut out = String::new();
    for chunk in bytes.chunks(3) {
        let bits = chunk.iter().enumerate().fold(0u32, |acc, (i, &b)| acc | u32::from(b) << (16 - 8 * i));
        for i in 0..4 {
            out.push(if i <= chunk.len() { SYMBOLS[(bits >> (18 - 6 * i) & 63) as usize] as char } else { '=' });
        }
    }
    out
}

/// The GIF's quality against the frames: the mean and the worst PSNR.
fn quality(frames: &[RgbImage], shown: &[RgbImage]) -> (f64, f64) {
    let db: Vec<f64> = frames.iter().zip(shown).map(|(a, b)| psnr(a, b).min(99.0)).collect();
    (db.iter().sum::<f64>() / db.len() as f64, db.iter().copied().fold(f64::INFINITY, f64::min))
}

#[test]
fn gifs_and_apngs_play_in_chromium_the_apng_exactly_and_the_gif_at_the_target() {
    let dir = tempfile::tempdir().expect("a directory");
    let d = dir.path();
    let browser = Browser::start((400, 300));
    // A page of its own origin, where WebCodecs are allowed.
    std::fs::write(d.join("page.html"), "<!doctype html><title>animations</title>").expect("written");
    browser.goto(&format!("file://{}", d.join("page.html").display()));
    // Every animation, small; anim_colours's colours go round its loop.
    for (name, size) in [("anim_colours", (64, 48)), ("anim_fig5_1", (64, 48)), ("anim_light", (64, 48))] {
        let (scene, count, rate) = small(d, name, size);
        let frames = frames(d, &scene, count);
        host_sim(d, &[&scene, "a.gif", "-q"]);
        host_sim(d, &[&scene, "a.png", "-q"]);
        // The GIF: its delays add up to the loop (GIF counts hundredths of
        // a second), it loops forever, and looks like the frames.
        let gif = play(&browser, &std::fs::read(d.join("a.gif")).expect("the GIF"), "image/gif", size);
        assert_eq!((gif.frames.len(), gif.shown_width), (count as usize, u64::from(size.0)), "{name}");
        assert_eq!(gif.repetitions, f64::INFINITY, "{name}: the GIF loops");
        let loop_length: u64 = gif.durations.iter().sum();
        assert_eq!(loop_length, 10_000 * ((100 * u64::from(count) + u64::from(rate) / 2) / u64::from(rate)), "{name}");
        // Nothing shimmers: a pixel the frame did not change shows what it
        // showed.
        for k in 1..frames.len() {
            let (before, now) = (&frames[k - 1].data, &frames[k].data);
            let kept = (0..now.len() / 3).filter(|&i| before[3 * i..3 * i + 3] == now[3 * i..3 * i + 3]);
            let shimmer =
                kept.filter(|&i| gif.frames[k - 1].data[3 * i..3 * i + 3] != gif.frames[k].data[3 * i..3 * i + 3]);
            assert_eq!(shimmer.count(), 0, "{name}: frame {k} changes pixels its frame did not");
        }
        let (mean, worst) = quality(&frames, &gif.frames);
        println!("{name} at {}×{}, {count} frames: GIF {mean:.2} dB mean, {worst:.2} dB worst", size.0, size.1);
        assert!(mean >= 45.0 && worst >= 40.0, "{name}: {mean:.2} dB mean, {worst:.2} dB worst");
        // The APNG: host-sim's frames bit for bit, at the scene's rate.
        let apng = play(&browser, &std::fs::read(d.join("a.png")).expect("the APNG"), "image/png", size);
        assert_eq!(apng.repetitions, f64::INFINITY, "{name}: the APNG loops");
        assert_eq!(apng.frames.len(), count as usize, "{name}");
        for (k, (shown, frame)) in apng.frames.iter().zip(&frames).enumerate() {
            assert!(shown == frame, "{name}: APNG frame {k} is not host-sim's frame");
        }
        // Chromium keeps a frame's delay in whole milliseconds.
        assert!(apng.durations.iter().all(|&t| t.abs_diff(1_000_000 / u64::from(rate)) < 1000), "{:?}", apng.durations);
    }
}

/// What ffprobe reads of `file`: its frames counted, its frame rate
/// (`r_frame_rate`), its average rate and its stream's duration.
fn probe(file: &Path) -> (u64, String, String, Option<f64>) {
    let output = std::process::Command::new("ffprobe")
        .args(["-v", "error", "-count_frames", "-select_streams", "v:0"])
        .args(["-show_entries", "stream=nb_read_frames,r_frame_rate,avg_frame_rate,duration", "-of", "json"])
        .arg(file)
        .output()
        .expect("ffprobe is missing: install Debian's ffmpeg (scripts/test-all does)");
    assert!(output.status.success(), "ffprobe {}: {}", file.display(), String::from_utf8_lossy(&output.stderr));
    let v: Value = serde_json::from_slice(&output.stdout).expect("ffprobe's JSON");
    let stream = &v["streams"][0];
    let text = |key: &str| stream[key].as_str().unwrap_or_default().to_string();
    let frames = text("nb_read_frames").parse().expect("a frame count");
    (frames, text("r_frame_rate"), text("avg_frame_rate"), text("duration").parse().ok())
}

#[test]
fn ffprobe_reads_the_frame_count_and_rate_of_every_animated_file() {
    let dir = tempfile::tempdir().expect("a directory");
    let d = dir.path();
    for (name, size) in [("anim_fig5_1", (32, 24)), ("anim_colours", (32, 24))] {
        let (scene, count, per_second) = small(d, name, size);
        let want = format!("{per_second}/1");
        for (out, palette) in [("a.gif", None), ("b.gif", Some("dither")), ("a.png", None), ("b.png", Some("scan"))] {
            let mut args = vec![scene.as_str(), out, "-q"];
            args.extend(palette.iter().flat_map(|p| ["--palette", p]));
            host_sim(d, &args);
            let (frames, rate, average, duration) = probe(&d.join(out));
            assert_eq!(frames, u64::from(count), "{name} as {out} {palette:?}");
            if out.ends_with(".gif") {
                // GIF counts hundredths of a second: 24 frames a second are
                // delays of 4 and 5, the loop exactly its length.
                let length = f64::from(count) / f64::from(per_second);
                assert_eq!(rate, want, "{name} as {out} {palette:?}");
                assert!(duration.is_some_and(|t| (t - length).abs() < 0.006), "{name} as {out}: {duration:?}");
            } else {
                assert_eq!(average, want, "{name} as {out} {palette:?}");
            }
        }
    }
}
