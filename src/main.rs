use clap::Parser;

fn main() {
    let cli = vibrobed::cli::Cli::parse();
    std::process::exit(vibrobed::cli::main_with(cli));
}
