//! The Pico benchmark: builds a Pico template (`examples/pico-st7789`, the
//! default, or `examples/pico-ssd1306`) for each scene, runs it on the
//! emulated Pico and prints Markdown tables (the ones in BENCHMARKS.md):
//! the cycles to start, to parse and index the scene and to render it into
//! the panel on both cores (240×240 on the ST7789; 128×64 on the SSD1306,
//! then sent over I2C), the seconds from scene text to picture at the clock
//! the firmware sets (the emulator reads it from the firmware's clock
//! registers: 200 MHz, the template's),
//! the same without the bus fabric's contention (each build runs twice:
//! the cores waiting for each other at the SRAM banks as on the chip, and
//! not), the firmware's flash and the SRAM it takes (its statics, and the
//! code copied there at boot); then each core's busy and waiting cycles,
//! its stalls on flash and on the other core, the contested accesses to
//! the striped banks, and the flash cache's reads and misses.
//!
//!     cargo run --release -p octrace-tests --bin pico-bench [--template pico-st7789|pico-ssd1306] [--code-in parse-and-render|render|sram|flash] [--order rows|progressive] [scene...]
//!
//! Cycles are the emulator's: the Cortex-M0+'s timings, both cores in
//! lockstep on the bus fabric, the flash behind its XIP cache with the QSPI
//! reads of the firmware's own boot2 (`emulator/`, whose README says what
//! it leaves out).

use octrace_tests::firmware::Sizes;
use octrace_tests::pico::{self, Build, Contention, Cycles, Template};

const USAGE: &str =
    "usage: pico-bench [--template pico-st7789|pico-ssd1306] [--code-in parse-and-render|render|sram|flash] \
                     [--order rows|progressive] [scene...]";

fn main() {
    let mut template = Template::St7789;
    let mut code_in = pico::DEFAULT_CODE_IN.to_owned();
    let mut order = "rows".to_owned();
    let mut scenes = Vec::new();
    let mut args = std::env::args().skip(1);
    while let Some(arg) = args.next() {
        let value = |name: &str, allowed: &[&str], value: Option<String>| match value {
            Some(v) if allowed.contains(&v.as_str()) => v,
            _ => usage(&format!("{name} takes one of {}", allowed.join(", "))),
        };
        match arg.as_str() {
            "--code-in" => {
                code_in = value("--code-in", &[pico::DEFAULT_CODE_IN, "render", "sram", "flash"], args.next())
            }
            "--order" => order = value("--order", &["rows", "progressive"], args.next()),
            "--template" => {
                let names = Template::ALL.map(Template::name);
                let name = value("--template", &names, args.next());
                template = Template::ALL.into_iter().find(|t| t.name() == name).unwrap_or(template);
            }
            flag if flag.starts_with('-') => usage(&format!("unknown option {flag}")),
            _ => scenes.push(arg),
        }
    }
    if scenes.is_empty() {
        scenes = ["fig5_1", "fig5_3", "fig5_5"].map(String::from).to_vec();
    }
    let dir = tempfile::tempdir().expect("a temporary directory");
    let mut rows = Vec::new();
    let mut failures = 0;
    for scene in &scenes {
        let build = Build { template, scene, code_in: &code_in, order: &order };
        let measured = pico::build(&build).and_then(|elf| {
            // Both runs at once: they share nothing but the ELF.
            let (with, without) = std::thread::scope(|s| {
                let run = |contention, png: &str| {
                    let (elf, png) = (&elf, dir.path().join(png));
                    s.spawn(move || pico::run_with(elf, &png, contention))
                };
                let with = run(Contention::On, "with.png");
                let without = run(Contention::Off, "without.png");
                (with.join().expect("a run's thread"), without.join().expect("a run's thread"))
            });
            Ok((with?, without?, Sizes::of(&elf)?, pico::sram_code_bytes(&elf)?))
        });
        match measured {
            Ok(row) => rows.push((build.name(), row)),
            Err(e) => {
                eprintln!("pico-bench: {}: {}", build.name(), e.lines().next().unwrap_or(""));
                failures += 1;
            }
        }
    }

    let millions = |cycles: u64| cycles as f64 / 1e6;
    // The clock the firmware set, as the emulator read it from its registers.
    let clocks: Vec<f64> = rows.iter().map(|(_, (c, ..))| c.clock_hz).collect();
    let clock = match clocks.first() {
        Some(&hz) if clocks.iter().all(|&c| c == hz) => format!("{:.0} MHz", hz / 1e6),
        _ => "the clock each set".to_owned(),
    };
    let sizes_text = |sizes: &Sizes, sram_code: u64| {
        format!(
            "{:.1} KiB | {:.1} + {:.1} KiB",
            (sizes.text + sizes.data) as f64 / 1024.0,
            (sizes.data + sizes.bss) as f64 / 1024.0,
            sram_code as f64 / 1024.0
        )
    };
    if template == Template::Ssd1306 {
        // The picture is traced into the panel's buffer, then sent.
        println!("| build | start-up | parse and index | render | picture over I2C | scene to picture at {clock} | flash | SRAM: statics + code |");
        println!("| --- | ---: | ---: | ---: | ---: | ---: | ---: | ---: |");
        for (name, (c, _, sizes, sram_code)) in &rows {
            let seconds = |cycles: u64| c.seconds(cycles);
            println!(
                "| {name} | {:.1} M cycles ({:.3} s) | {:.1} M cycles ({:.3} s) | {:.1} M cycles ({:.3} s) | {:.2} M cycles ({:.3} s) | **{:.1} M cycles, {:.3} s** | {} |",
                millions(c.start_up),
                c.start_up_seconds,
                millions(c.parse_and_index),
                seconds(c.parse_and_index),
                millions(c.render),
                seconds(c.render),
                millions(c.transfer.unwrap_or(0)),
                seconds(c.transfer.unwrap_or(0)),
                millions(c.to_picture_cycles()),
                c.to_picture_seconds(),
                sizes_text(sizes, *sram_code),
            );
        }
    } else {
        println!("| build | parse and index | render | scene to picture at {clock} | without contention | whole panel drawn once | flash | SRAM: statics + code |");
        println!("| --- | ---: | ---: | ---: | ---: | ---: | ---: | ---: |");
        for (name, (c, free, sizes, sram_code)) in &rows {
            let seconds = |cycles: u64| c.seconds(cycles);
            println!(
                "| {name} | {:.1} M cycles ({:.3} s) | {:.1} M cycles ({:.3} s) | **{:.1} M cycles, {:.3} s** | {:.3} s (+{:.1} %) | {:.3} s | {} |",
                millions(c.parse_and_index),
                seconds(c.parse_and_index),
                millions(c.render),
                seconds(c.render),
                millions(c.to_picture_cycles()),
                c.to_picture_seconds(),
                free.to_picture_seconds(),
                100.0 * (c.to_picture_seconds() / free.to_picture_seconds() - 1.0),
                seconds(c.first_full_panel),
                sizes_text(sizes, *sram_code),
            );
        }
    }
    println!();
    println!(
        "| build | core 0 busy (on flash; on core 1) | core 0 waiting | core 1 busy (on flash; on core 0) | core 1 waiting | contested SRAM0-3 accesses | flash reads | cache misses |"
    );
    println!("| --- | ---: | ---: | ---: | ---: | ---: | ---: | ---: |");
    for (name, (c, _, _, _)) in &rows {
        let Cycles { busy, stalled, bus_stalled, waiting, .. } = c;
        println!(
            "| {name} | {:.1} M ({:.1} M; {:.1} M) | {:.1} M | {:.1} M ({:.1} M; {:.1} M) | {:.1} M | {:.1} M | {:.1} M | {:.2} M |",
            millions(busy[0]),
            millions(stalled[0]),
            millions(bus_stalled[0]),
            millions(waiting[0]),
            millions(busy[1]),
            millions(stalled[1]),
            millions(bus_stalled[1]),
            millions(waiting[1]),
            millions(c.striped_contested),
            millions(c.flash_reads),
            millions(c.cache_misses),
        );
    }
    // A build that could not be measured is not a figure: the run fails.
    if failures > 0 {
        eprintln!("pico-bench: {failures} build(s) failed");
        std::process::exit(1);
    }
}

fn usage(message: &str) -> ! {
    eprintln!("pico-bench: {message}\n{USAGE}");
    std::process::exit(2);
}
