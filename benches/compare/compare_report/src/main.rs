//! BENCHMARKS.md and one Pareto plot per scene from the JSON lines of the peer comparison
//! (`out/compare/all.jsonl`, written by `benches/compare/run_all.sh`).
//!
//! ```text
//! compare_report [--input out/compare/all.jsonl] [--markdown BENCHMARKS.md] [--plots docs/benchmarks]
//! ```
//!
//! Per scene: a PNG of error magnitude (or the scene's quantity) against ms per step on log-log
//! axes, one series per engine knob, with the Pareto front; in the markdown the machine, date and
//! command of the run, who is on each front, how this crate's cases stand against each peer's
//! front, the best case of each engine and a table of every case.

mod data;
mod markdown;
mod pareto;
mod plot;
mod scenes;

use clap::Parser;
use std::path::{Component, Path, PathBuf};
use std::process::ExitCode;

/// Writes BENCHMARKS.md and the Pareto plots from the comparison's JSON lines.
#[derive(Parser)]
struct Args {
    /// The JSON lines of every engine (and the driver's `run` records).
    #[arg(long, default_value = "out/compare/all.jsonl")]
    input: PathBuf,
    /// The markdown file to write.
    #[arg(long, default_value = "BENCHMARKS.md")]
    markdown: PathBuf,
    /// The folder of the plots (created if missing).
    #[arg(long, default_value = "docs/benchmarks")]
    plots: PathBuf,
}

/// Runs the report, printing an error instead of panicking.
fn main() -> ExitCode {
    match run(&Args::parse()) {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("error: {e}");
            ExitCode::FAILURE
        }
    }
}

/// Reads the input, draws every scene's plot and writes the markdown.
fn run(args: &Args) -> Result<(), Box<dyn std::error::Error>> {
    let (run, cases) = data::read(&args.input)?;
    std::fs::create_dir_all(&args.plots).map_err(|e| format!("{}: {e}", args.plots.display()))?;
    let mut doc = markdown::head(&run, &cases, &args.input.display().to_string());
    let image_dir = relative(args.markdown.parent().unwrap_or(Path::new("")), &args.plots)?;
    for scene in scenes::scenes() {
        let mine: Vec<&data::Case> = cases.iter().filter(|c| c.scene == scene.name).collect();
        if mine.is_empty() {
            continue;
        }
        let panels: Vec<_> = scene
            .panels
            .iter()
            .map(|panel| (panel, pareto::points(&mine, panel)))
            .collect();
        let series = series_of(&panels);
        let file = format!("{}.png", scene.name);
        plot::draw(&args.plots.join(&file), scene.title, &panels, &series)
            .map_err(|e| format!("{}: {e}", args.plots.join(&file).display()))?;
        let image = image_dir.join(&file);
        doc.push_str(&markdown::section(
            &scene,
            &panels,
            &mine,
            &image.to_string_lossy(),
        ));
        eprintln!("{}: {} cases", scene.name, mine.len());
    }
    std::fs::write(&args.markdown, doc).map_err(|e| format!("{}: {e}", args.markdown.display()))?;
    eprintln!(
        "wrote {} and {}/",
        args.markdown.display(),
        args.plots.display()
    );
    Ok(())
}

/// The series plotted in a scene: engines in the tables' order, each engine's series sorted.
fn series_of(panels: &[(&scenes::Panel, Vec<pareto::Point>)]) -> Vec<String> {
    let mut series: Vec<(usize, String)> = panels
        .iter()
        .flat_map(|(_, points)| points.iter())
        .map(|p| {
            let rank = markdown::ENGINES
                .iter()
                .position(|&e| e == p.case.engine)
                .unwrap_or(markdown::ENGINES.len());
            (rank, p.case.series.clone())
        })
        .collect();
    series.sort();
    series.dedup();
    series.into_iter().map(|(_, s)| s).collect()
}

/// The path of `to` relative to the folder `from` (both taken from the current directory; an
/// empty path is the current directory).
fn relative(from: &Path, to: &Path) -> std::io::Result<PathBuf> {
    let here = |p: &Path| {
        if p.as_os_str().is_empty() {
            std::path::absolute(".")
        } else {
            std::path::absolute(p)
        }
    };
    let (from, to) = (here(from)?, here(to)?);
    let (from, to) = (normal(&from), normal(&to));
    let common = from.iter().zip(&to).take_while(|(a, b)| a == b).count();
    let mut path: PathBuf =
        std::iter::repeat_n(Component::ParentDir, from.len() - common).collect();
    path.extend(&to[common..]);
    Ok(path)
}

/// The components of `path` without `.`.
fn normal(path: &Path) -> Vec<Component<'_>> {
    path.components()
        .filter(|c| *c != Component::CurDir)
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn plots_are_linked_relative_to_the_markdown() {
        let path = relative(Path::new(""), Path::new("docs/benchmarks")).unwrap();
        assert_eq!(path, PathBuf::from("docs/benchmarks"));
        let path = relative(Path::new("a/b"), Path::new("a/c/d")).unwrap();
        assert_eq!(path, PathBuf::from("../c/d"));
    }
}
