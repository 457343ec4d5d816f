//! host-sim's command line built beside the tests, so that they can run it
//! as a program (under GNU parallel, with a scheduler's environment) exactly
//! as `host-sim` runs: both are `host_sim::cli::run`.

fn main() {
    let code = host_sim::cli::run(std::env::args_os(), &mut std::io::stdout(), &mut std::io::stderr());
    std::process::exit(code);
}
