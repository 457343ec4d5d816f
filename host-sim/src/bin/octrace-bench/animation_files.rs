//! The `animfiles` table (issue 49): each animation's GIF and APNG as
//! host-sim writes them, against ffmpeg's palettegen (stats_mode=full) /
//! paletteuse (dither=sierra2_4a) GIF of the same frames and against the
//! APNG host-sim wrote before (every frame whole): sizes, and the GIFs'
//! quality as ffmpeg decodes them, PSNR over RGB against host-sim's
//! frames (`--frame K`), mean and worst over the loop, and through a blur
//! of one pixel (issue 42's eye).

use crate::measure::BenchError;
use host_sim::animation::{render_frames, AnimationOptions, ApngWriter, GifWriter};
use host_sim::{all_cores, RenderOptions, RgbImage};
use octrace_core::scene::Frames;
use octrace_images::formats::Image;
use octrace_images::palette::psnr;
use octrace_images::panel::blurred_psnr;
use std::path::Path;
use std::process::Command;
use std::time::Instant;

/// The animations and sizes of issue 49's targets, and the scene whose
/// colours change most over its loop.
const CASES: [(&str, (u32, u32)); 6] = [
    ("anim_fig5_1", (640, 480)),
    ("anim_fig5_1", (1024, 768)),
    ("anim_light", (640, 480)),
    ("anim_light", (1024, 768)),
    ("anim_colours", (640, 480)),
    ("anim_colours", (1024, 768)),
];

/// Quality of a GIF's frames against the render's.
struct Quality {
    mean: f64,
    worst: f64,
    blurred: f64,
}

fn quality(frames: &[RgbImage], decoded: &[RgbImage]) -> Quality {
    let plain: Vec<f64> = frames.iter().zip(decoded).map(|(a, b)| psnr(a, b).min(99.0)).collect();
    let blurred: Vec<f64> = frames.iter().zip(decoded).map(|(a, b)| blurred_psnr(a, b).min(99.0)).collect();
    let mean = |v: &[f64]| v.iter().sum::<f64>() / v.len().max(1) as f64;
    Quality { mean: mean(&plain), worst: plain.iter().copied().fold(f64::INFINITY, f64::min), blurred: mean(&blurred) }
}

/// `file`'s frames as ffmpeg decodes them (each once, as composed).
fn ffmpeg_frames(file: &Path, (w, h): (u32, u32)) -> Result<Vec<RgbImage>, BenchError> {
    let output = Command::new("ffmpeg")
        .args(["-v", "error", "-i"])
        .arg(file)
        .args(["-f", "rawvideo", "-pix_fmt", "rgb24", "-fps_mode", "passthrough", "-"])
        .output()
        .map_err(|e| BenchError::Tool(format!("ffmpeg: {e} (apt-get install ffmpeg)")))?;
    if !output.status.success() {
        return Err(BenchError::Tool(format!("ffmpeg: {}", String::from_utf8_lossy(&output.stderr))));
    }
    let size = 3 * (w * h) as usize;
    Ok(output.stdout.chunks_exact(size).map(|d| RgbImage { width: w, height: h, data: d.to_vec() }).collect())
}

/// The APNG host-sim wrote before issue 49: every frame whole, RGB, the
/// PNG encoder's default compression.
fn whole_frames_apng(frames: &[RgbImage], rate: u32) -> Result<usize, BenchError> {
    let (w, h) = (frames[0].width, frames[0].height);
    let mut out = Vec::new();
    let mut encoder = png::Encoder::new(&mut out, w, h);
    encoder.set_color(png::ColorType::Rgb);
    encoder.set_depth(png::BitDepth::Eight);
    let failed = |e: png::EncodingError| BenchError::Tool(format!("png: {e}"));
    encoder.set_animated(frames.len() as u32, 0).map_err(failed)?;
    encoder.set_frame_delay(1, rate as u16).map_err(failed)?;
    let mut writer = encoder.write_header().map_err(failed)?;
    for frame in frames {
        writer.write_image_data(&frame.data).map_err(failed)?;
    }
    writer.finish().map_err(failed)?;
    Ok(out.len())
}

fn kb(bytes: usize) -> String {
    format!("{:.0} KB", bytes as f64 / 1000.0)
}

pub(crate) fn table(dir: &Path) -> Result<(), BenchError> {
    let work = std::env::temp_dir().join(format!("octrace-bench-animfiles-{}", std::process::id()));
    std::fs::create_dir_all(&work).map_err(|e| BenchError::Tool(format!("{}: {e}", work.display())))?;
    let result = cases(dir, &work);
    let _ = std::fs::remove_dir_all(&work);
    result
}

fn cases(dir: &Path, work: &Path) -> Result<(), BenchError> {
    println!("### Animated GIF and APNG (issue 49): host-sim against ffmpeg on the same frames\n");
    println!(
        "GIF dB: PSNR over RGB against host-sim's frames, as ffmpeg decodes the file: mean over the loop / worst \
         frame / mean through a blur of σ = 1 pixel. ffmpeg: palettegen=stats_mode=full, paletteuse=dither=sierra2_4a.\n"
    );
    println!(
        "| scene | size | frames | GIF | GIF dB | ffmpeg's GIF | ffmpeg's dB | APNG | APNG before (whole frames) | APNG \
         lossless | writing the GIF |"
    );
    println!("| --- | --- | ---: | ---: | --- | ---: | --- | ---: | ---: | --- | ---: |");
    for (name, size) in CASES {
        let path = dir.join(format!("{name}.txt"));
        let bytes = std::fs::read(&path)
            .map_err(|e| BenchError::Scene { path: path.clone(), error: host_sim::LoadError::Io(e) })?;
        let mut scene = host_sim::new_scene();
        let loaded = host_sim::load_bytes(&path.display().to_string(), &bytes, &mut scene)
            .map_err(|error| BenchError::Scene { path: path.clone(), error })?;
        let frames: Frames = loaded.frames.expect("an animation");
        let options = AnimationOptions {
            render: RenderOptions { size: Some(size), threads: all_cores(), ..RenderOptions::default() },
            coherence: true,
        };
        let (mut gif, mut apng_bytes) = (GifWriter::new(Vec::new(), size.0, size.1, frames).map_err(io)?, Vec::new());
        let mut apng = ApngWriter::new(&mut apng_bytes, size.0, size.1, frames).map_err(io)?;
        let mut images = Vec::new();
        let mut writing = std::time::Duration::ZERO;
        render_frames(&bytes, frames.all(), &options, &|_| {}, &mut |_, frame| {
            let started = Instant::now();
            gif.frame(&Image::Rgb(frame.image.clone()), frame.retraced.as_deref())?;
            writing += started.elapsed();
            apng.frame(&frame.image.data, frame.retraced.as_deref())?;
            images.push(frame.image.clone());
            Ok(())
        })
        .map_err(|e| BenchError::Tool(format!("{name}: {e:?}")))?;
        apng.finish().map_err(io)?;
        let started = Instant::now();
        let ours = gif.finish().map_err(io)?;
        writing += started.elapsed();
        let (ours_path, apng_path) = (work.join("ours.gif"), work.join("ours.png"));
        std::fs::write(&ours_path, &ours).map_err(io)?;
        std::fs::write(&apng_path, &apng_bytes).map_err(io)?;
        // ffmpeg's GIF from the same frames, as PNG files (a directory a
        // case: ffmpeg reads every file of the pattern).
        let pngs = work.join(format!("{name}-{}x{}", size.0, size.1));
        std::fs::create_dir_all(&pngs).map_err(io)?;
        for (k, image) in images.iter().enumerate() {
            let mut file = std::fs::File::create(pngs.join(format!("f{k:05}.png"))).map_err(io)?;
            octrace_images::formats::write(&Image::Rgb(image.clone()), octrace_images::formats::Format::Png, &mut file)
                .map_err(|e| BenchError::Tool(e.to_string()))?;
        }
        let theirs_path = work.join("ffmpeg.gif");
        let status = Command::new("ffmpeg")
            .args(["-v", "error", "-y", "-framerate", &frames.rate.to_string(), "-i"])
            .arg(pngs.join("f%05d.png"))
            .args(["-vf", "split[a][b];[a]palettegen=stats_mode=full[p];[b][p]paletteuse=dither=sierra2_4a"])
            .arg(&theirs_path)
            .status()
            .map_err(|e| BenchError::Tool(format!("ffmpeg: {e} (apt-get install ffmpeg)")))?;
        if !status.success() {
            return Err(BenchError::Tool(format!("ffmpeg could not make the GIF of {name}")));
        }
        let theirs = std::fs::metadata(&theirs_path).map_err(io)?.len() as usize;
        let ours_q = quality(&images, &ffmpeg_frames(&ours_path, size)?);
        let theirs_q = quality(&images, &ffmpeg_frames(&theirs_path, size)?);
        let lossless = ffmpeg_frames(&apng_path, size)? == images;
        let _ = std::fs::remove_dir_all(&pngs);
        let db = |q: &Quality| format!("{:.1} / {:.1} / {:.1}", q.mean, q.worst, q.blurred);
        println!(
            "| {name} | {}×{} | {} | {} | {} | {} | {} | {} | {} | {} | {:.2} s |",
            size.0,
            size.1,
            frames.count,
            kb(ours.len()),
            db(&ours_q),
            kb(theirs),
            db(&theirs_q),
            kb(apng_bytes.len()),
            kb(whole_frames_apng(&images, frames.rate)?),
            if lossless { "yes" } else { "**no**" },
            writing.as_secs_f64()
        );
    }
    println!();
    Ok(())
}

fn io(e: std::io::Error) -> BenchError {
    BenchError::Tool(e.to_string())
}
