fn main() {
    std::process::exit(host_sim::run(std::env::args_os(), &mut std::io::stderr()));
}
