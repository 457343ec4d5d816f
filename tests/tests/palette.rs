//! 256-colour output and the image files, end to end: every scene in every
//! palette mode, written in every format, decoded by octrace's reader (and
//! the PNG by the `png` crate too; the Targa writer meets ffmpeg's reader in
//! octrace-images' tests), and converted between formats without loss.
//! Prints the palette entries used and the PSNR against truecolour
//! (`-- --nocapture`).

use host_sim::{load_bytes, load_file, new_scene, render, RenderOptions};
use octrace_images::formats::{self, Format, Image};
use octrace_images::palette::{self, PaletteMode};
use octrace_tests::{scene_path, scenes};

const FORMATS: [Format; 3] = [Format::Png, Format::Tga, Format::Ras];

fn encode(image: &Image, format: Format) -> Vec<u8> {
    let mut bytes = Vec::new();
    formats::write(image, format, &mut bytes).unwrap();
    bytes
}

/// The PNG as the `png` crate decodes it: (indexed?, palette entries, RGB).
fn png_decoded(bytes: &[u8]) -> (bool, usize, Vec<u8>) {
    let mut reader = png::Decoder::new(std::io::Cursor::new(bytes)).read_info().unwrap();
    let info = reader.info();
    let indexed = info.color_type == png::ColorType::Indexed;
    let palette = info.palette.as_ref().map(|p| p.to_vec()).unwrap_or_default();
    let mut buf = vec![0; reader.output_buffer_size().unwrap()];
    let frame = reader.next_frame(&mut buf).unwrap();
    buf.truncate(frame.buffer_size());
    let rgb = if indexed {
        assert_eq!(frame.bit_depth, png::BitDepth::Eight);
        buf.iter().flat_map(|&i| palette[3 * i as usize..3 * i as usize + 3].to_vec()).collect()
    } else {
        buf
    };
    (indexed, palette.len() / 3, rgb)
}

fn check_files(name: &str, image: &Image) {
    let rgb = image.to_rgb();
    for format in FORMATS {
        let bytes = encode(image, format);
        assert_eq!(&formats::read(&bytes).unwrap(), image, "{name}: {format:?} round trip");
        match format {
            Format::Png => {
                let (indexed, entries, decoded) = png_decoded(&bytes);
                assert_eq!(indexed, matches!(image, Image::Indexed { .. }), "{name}: PNG colour type");
                assert!(entries <= 256, "{name}: {entries} PLTE entries");
                assert_eq!(decoded, rgb.data, "{name}: PNG pixels");
            }
            Format::Tga | Format::Ras => {}
        }
    }
}

#[test]
fn every_scene_in_every_mode_and_format() {
    println!("{:<8} {:<7} {:>8} {:>9}", "scene", "mode", "colours", "PSNR dB");
    for (name, path) in scenes() {
        let mut scene = new_scene();
        load_file(&path, &mut scene).unwrap();
        let rendered =
            render(&mut scene, &RenderOptions { size: Some((96, 72)), threads: 2, ..Default::default() }).unwrap();
        for mode in PaletteMode::ALL {
            let image = palette::apply(&rendered.image, &rendered.objects, mode);
            if let Image::Indexed { palette, .. } = &image {
                assert!(palette.len() <= 256, "{name} {mode:?}");
            }
            let colours = palette::colors_used(&image);
            let quality = palette::psnr(&rendered.image, &image.to_rgb());
            println!("{name:<8} {:<7} {colours:>8} {quality:>9.1}", mode.name());
            assert!(mode == PaletteMode::None || colours <= 256, "{name} {mode:?}: {colours} colours");
            // Floors that catch a broken mode: gray loses hue, ordered
            // dithering trades per-pixel error (a 51-level step) for the
            // right mean, and outlines are black by design.
            let floor = match mode {
                PaletteMode::None => f64::INFINITY,
                PaletteMode::Scan => 30.0,
                PaletteMode::Dither => 18.0,
                PaletteMode::Coarse => 0.0, // checked against dither below
                PaletteMode::Gray => 8.0,
            };
            assert!(quality >= floor, "{name} {mode:?}: {quality:.1} dB");
            check_files(&format!("{name} {mode:?}"), &image);
        }
        // coarse = dither, with entry 0 (black) wherever the object differs
        // from the left or upper neighbour's.
        let indices = |mode| match palette::apply(&rendered.image, &rendered.objects, mode) {
            Image::Indexed { indices, .. } => indices,
            Image::Rgb(_) => panic!("indexed"),
        };
        let (dither, coarse) = (indices(PaletteMode::Dither), indices(PaletteMode::Coarse));
        let (w, objects) = (96, &rendered.objects);
        for (i, (&d, &c)) in dither.iter().zip(&coarse).enumerate() {
            let edge = (i % w > 0 && objects[i - 1] != objects[i]) || (i >= w && objects[i - w] != objects[i]);
            assert_eq!(c, if edge { 0 } else { d }, "{name}: coarse pixel {i}");
        }
    }
}

#[test]
fn coarse_outlines_a_bspline_patch_not_its_triangles() {
    // freeform: one 64×64 patch (7,938 triangles) and four spheres. Each
    // patch is one object as written, so the pixels see at most five, and
    // coarse outlines stay few (they once drew the whole triangle mesh).
    let mut scene = new_scene();
    load_file(&scene_path("freeform"), &mut scene).unwrap();
    let rendered = render(&mut scene, &RenderOptions { size: Some((160, 120)), ..Default::default() }).unwrap();
    let mut seen: Vec<u32> = rendered.objects.iter().copied().filter(|&o| o != host_sim::NO_OBJECT).collect();
    seen.sort_unstable();
    seen.dedup();
    assert_eq!(seen.len(), 5, "objects seen (first 8): {:?}", &seen[..seen.len().min(8)]);
    let Image::Indexed { indices, .. } = palette::apply(&rendered.image, &rendered.objects, PaletteMode::Coarse) else {
        panic!("indexed")
    };
    let black = indices.iter().filter(|&&i| i == 0).count();
    assert!(black * 20 < indices.len(), "{black} of {} pixels are outline", indices.len());
}

#[test]
fn one_colour_and_one_pixel_images() {
    let mut scene = new_scene();
    load_bytes("flat", b"BACKGROUND 0.2 0.4 0.6 RASTER 7 5", &mut scene).unwrap();
    for size in [(7, 5), (1, 1)] {
        let rendered = render(&mut scene, &RenderOptions { size: Some(size), ..Default::default() }).unwrap();
        for mode in PaletteMode::ALL {
            let image = palette::apply(&rendered.image, &rendered.objects, mode);
            assert_eq!((image.width(), image.height()), size);
            // Dithering spreads a colour between the cube's neighbours (at
            // most two levels per channel); the others keep one colour.
            let most = if matches!(mode, PaletteMode::Dither | PaletteMode::Coarse) { 8 } else { 1 };
            assert!(palette::colors_used(&image) <= most, "{mode:?}");
            check_files(&format!("flat {size:?} {mode:?}"), &image);
        }
        // The scan table keeps the colour exactly.
        let scan = palette::apply(&rendered.image, &rendered.objects, PaletteMode::Scan);
        assert_eq!(scan.to_rgb(), rendered.image);
    }
}

#[test]
fn scan_maps_more_than_256_colours_onto_256() {
    let path = scene_path("fig5_3");
    let mut scene = new_scene();
    load_file(&path, &mut scene).unwrap();
    let rendered = render(&mut scene, &RenderOptions { threads: 2, ..Default::default() }).unwrap();
    let truecolour = palette::colors_used(&Image::Rgb(rendered.image.clone()));
    assert!(truecolour > 256, "{truecolour}");
    let scan = palette::apply(&rendered.image, &rendered.objects, PaletteMode::Scan);
    let Image::Indexed { palette: table, .. } = &scan else { panic!("indexed") };
    assert!(table.len() <= 256);
    let quality = palette::psnr(&rendered.image, &scan.to_rgb());
    println!("fig5_3: {truecolour} colours onto {} entries, {quality:.1} dB", palette::colors_used(&scan));
    assert!(quality > 30.0, "{quality:.1} dB");
}

#[test]
fn host_sim_writes_and_converts_every_format() {
    let dir = tempfile::tempdir().unwrap();
    let scene = scene_path("fig5_1");
    let run = |args: &[&std::ffi::OsStr]| {
        let (mut out, mut err) = (Vec::new(), Vec::new());
        let mut all = vec![std::ffi::OsStr::new("host-sim")];
        all.extend_from_slice(args);
        let code = host_sim::cli::run(all, &mut out, &mut err);
        assert_eq!(code, 0, "{}", String::from_utf8_lossy(&err));
    };
    for mode in ["none", "scan", "dither", "coarse", "gray"] {
        let files: Vec<_> = ["png", "tga", "ras"].iter().map(|ext| dir.path().join(format!("{mode}.{ext}"))).collect();
        for file in &files {
            run(&[
                scene.as_os_str(),
                file.as_os_str(),
                "--size".as_ref(),
                "40x30".as_ref(),
                "--palette".as_ref(),
                mode.as_ref(),
                "-q".as_ref(),
            ]);
        }
        let read = |p: &std::path::Path| formats::read(&std::fs::read(p).unwrap()).unwrap();
        let first = read(&files[0]);
        assert_eq!(matches!(first, Image::Indexed { .. }), mode != "none", "{mode}");
        for file in &files[1..] {
            assert_eq!(read(file), first, "{mode}: {}", file.display());
        }
        // png → tga → ras → png, by extension and by --format.
        let (a, b, c) = (dir.path().join("a.tga"), dir.path().join("b.ras"), dir.path().join("c.img"));
        run(&["convert".as_ref(), files[0].as_os_str(), a.as_os_str()]);
        run(&["convert".as_ref(), a.as_os_str(), b.as_os_str()]);
        run(&["convert".as_ref(), b.as_os_str(), c.as_os_str(), "--format".as_ref(), "png".as_ref()]);
        assert_eq!(std::fs::read(&c).unwrap()[..8], *b"\x89PNG\r\n\x1a\n");
        assert_eq!(read(&c), first, "{mode}: converted");
    }
}

#[test]
fn convert_rejects_a_corrupt_file_and_leaves_nothing() {
    let dir = tempfile::tempdir().unwrap();
    let bad = dir.path().join("bad.ras");
    std::fs::write(&bad, [0x59, 0xa6, 0x6a, 0x95, 0, 0]).unwrap();
    let out = dir.path().join("out.png");
    let (mut stdout, mut stderr) = (Vec::new(), Vec::new());
    let code = host_sim::cli::run(
        ["host-sim".as_ref(), "convert".as_ref(), bad.as_os_str(), out.as_os_str()],
        &mut stdout,
        &mut stderr,
    );
    assert_ne!(code, 0);
    assert!(String::from_utf8_lossy(&stderr).contains("bad.ras"), "{}", String::from_utf8_lossy(&stderr));
    assert!(!out.exists());
}

#[test]
fn convert_says_a_file_that_is_no_image_is_none() {
    let dir = tempfile::tempdir().unwrap();
    // A scene file, given where an image is wanted: no signature, and no
    // Targa header either, whose image type its third byte would be.
    let scene = dir.path().join("scene.txt");
    std::fs::write(&scene, "FRAMES 48 24\nRASTER 240 180\nSPHERE 1 1 0 0 0\n").unwrap();
    let out = dir.path().join("out.png");
    let (mut stdout, mut stderr) = (Vec::new(), Vec::new());
    let code = host_sim::cli::run(
        ["host-sim".as_ref(), "convert".as_ref(), scene.as_os_str(), out.as_os_str()],
        &mut stdout,
        &mut stderr,
    );
    let err = String::from_utf8_lossy(&stderr);
    assert_eq!(code, 2, "{err}");
    assert!(err.contains("scene.txt: not a PNG, Targa or Sun raster image\n"), "{err}");
    assert!(!err.contains("Targa file") && !err.contains("image type"), "{err}");
    assert!(!out.exists());
}
