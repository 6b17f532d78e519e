//! `rapier-fvm`: runs `rapier_fvm` scenes headless, checks meshes, advises on a cheaper
//! scene within a target error and measures the cost model.
//!
//! See `rapier-fvm --help`, and `assets/scenes/README.md` for the scene format.

use clap::{Parser, Subcommand};
use rapier_fvm::integrate::SymplecticEuler;
use rapier_fvm::material::{Material, MaterialModel};
use rapier_fvm::mesh::import::{self, SurfaceOptions};
use rapier_fvm_runner::advise;
use rapier_fvm_runner::planar::{self, PlanarScene};
use rapier_fvm_runner::scene::{MemoryBudget, Scene, dimension_of};
use rapier_fvm_runner::sim::{self, RunOptions};
use std::io::IsTerminal;
use std::path::PathBuf;
use std::process::ExitCode;

/// Runs scenes of finite-volume soft bodies and rapier rigid bodies (described in TOML)
/// headless, checks meshes, finds a cheaper scene within a target error, and measures the
/// automatic integrator's costs on this machine.
///
/// Errors (a missing file, a malformed scene or mesh) print one line on stderr and exit with
/// status 1; wrong command-line arguments exit with status 2.
#[derive(Debug, Parser)]
#[command(name = "rapier-fvm", version, about, long_about)]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Debug, Subcommand)]
enum Command {
    /// Runs a scene and writes its results into a folder.
    ///
    /// Steps the scene frame by frame (progress bar on stderr when it is a terminal), then
    /// writes into the output folder: report.json (settings used, tets and nodes per body,
    /// integrator choices, each body's predicted and measured step cost, wall time and ms per
    /// frame, where the stepping went (soft steps by integrator and rigid partners, contact
    /// detection, rapier's steps), stability flags, every probe as a time series with its final
    /// value);
    /// paraview/<scene>.pvd with a .vtu per soft body per saved frame (displacement,
    /// velocity, Cauchy and von Mises stress); obj/surface_<frame>.obj
    /// (every body's surface, for Blender); pictures/view_<frame>.png and
    /// pictures/stress_<frame>.png (rendered views coloured by material and by von Mises
    /// stress); plots/<probe>.png (each probe against time). Prints a summary on stdout.
    /// A scene with `dimension = 2` in `[world]` is a 2D scene (soft bodies on triangles with
    /// rapier2d's rigid bodies): the same files, triangles at z = 0, pictures from the front.
    Run {
        /// The scene file (TOML; format in assets/scenes/README.md).
        scene: PathBuf,
        /// The output folder (created if needed; files in it are overwritten).
        #[arg(long, short)]
        out: PathBuf,
        /// Runs this long (s) instead of the scene's duration.
        #[arg(long)]
        duration: Option<f64>,
        /// Hides the progress bar.
        #[arg(long)]
        quiet: bool,
        /// The most memory the soft bodies may need, in GB (10⁹ bytes); default the memory
        /// available (`MemAvailable` in `/proc/meminfo`, 8 GB where that is unknown). A scene whose
        /// meshes are estimated to need more is refused, with the estimate, before any is built.
        /// For 3D scenes; a 2D scene's generators make at most ten million triangles each.
        #[arg(long, value_name = "GB")]
        memory_limit: Option<f64>,
    },
    /// Reports a mesh file's size, volume, quality and stable explicit time step.
    ///
    /// Reads Gmsh .msh (2.2, 4.1, ASCII or binary; 4.0), TetGen .node/.ele, VTK .vtu/.vtk, or a
    /// closed .obj/.stl/.msh surface (filled with tetrahedra), and prints the element and node
    /// counts (of hexahedra and their tetrahedra for a file of hexahedra), the volume (of the
    /// curved elements for quadratic tetrahedra and 27-node hexahedra), the smallest
    /// dihedral angle and radius ratio, the inverted and degenerate elements (and the folded
    /// quadratic ones), and the explicit integrator's critical and stable time steps for the
    /// material given.
    Check {
        /// The mesh file.
        mesh: PathBuf,
        /// Metres per file unit (0.001 for a file in millimetres).
        #[arg(long, default_value_t = 1.0)]
        scale: f64,
        /// Young's modulus (Pa) for the time step.
        #[arg(long, default_value_t = 1e6)]
        young: f64,
        /// Poisson's ratio for the time step.
        #[arg(long, default_value_t = 0.3)]
        poisson: f64,
        /// Density (kg/m³) for the time step.
        #[arg(long, default_value_t = 1000.0)]
        density: f64,
        /// Lattice cells across a surface's largest extent when it is filled (2 to 128).
        #[arg(long, default_value_t = 16)]
        cells_across: usize,
    },
    /// Finds a cheaper scene whose probes stay within a target error of the scene as written.
    ///
    /// Runs the scene (the reference: each soft body's peak strain, rotation and contact
    /// frames, the time per frame), then each alternative alone (per soft body another material
    /// model, linear elements for quadratic ones, half the cells; another integrator, a Newton
    /// tolerance a hundred times looser, half the coupling substeps), each measured by its
    /// largest probe error (the L2 distance of its samples from the reference's over the frames,
    /// relative to how far the reference's move from their first value) and its time per frame;
    /// then runs the set chosen greedily (largest saving first) whose errors add up to at most
    /// the target, dropping changes until it is within the target and faster than the scene.
    /// Writes into the output folder: recommended.toml (ready for `rapier-fvm run`),
    /// advice.json (every alternative's error, cost and verdict; predicted and measured error
    /// and cost of the recommendation) and trials/ (each run's output folder). Prints the table.
    Advise {
        /// The scene file (3D).
        scene: PathBuf,
        /// The output folder (created if needed; files in it are overwritten).
        #[arg(long, short)]
        out: PathBuf,
        /// The largest probe error allowed, relative (0.05 for 5 %).
        #[arg(long, default_value_t = 0.05)]
        target: f64,
        /// Runs each trial this long (s) instead of the scene's duration.
        #[arg(long)]
        duration: Option<f64>,
        /// Prints no line per trial on stderr.
        #[arg(long)]
        quiet: bool,
    },
    /// Measures the automatic integrator's cost model on this machine.
    ///
    /// Steps a soft cube free and dropped on the ground with each integrator forced (about half
    /// a minute), prints each case's time per frame, then the model as a scene's
    /// `[integrator.cost]` table, to paste into scenes run on this machine.
    Calibrate,
}

/// The exit status after a reader closed stdout early: a shell's for a program SIGPIPE ended.
const BROKEN_PIPE_STATUS: i32 = 141;

fn main() -> ExitCode {
    // A bug must still end in one line, not a backtrace.
    std::panic::set_hook(Box::new(|info| {
        let message = info
            .payload()
            .downcast_ref::<&str>()
            .map(|s| (*s).to_owned())
            .or_else(|| info.payload().downcast_ref::<String>().cloned())
            .unwrap_or_default();
        // A reader that stopped early (`rapier-fvm run ... | head -1`) closed stdout, and
        // `println!` panics: end as `cat` ends there, quietly, with 128 + SIGPIPE (`run` prints
        // its summary once its files are written).
        if message.starts_with("failed printing to stdout") {
            std::process::exit(BROKEN_PIPE_STATUS);
        }
        eprintln!("error: internal error: {message}");
    }));
    let cli = Cli::parse();
    let result = match cli.command {
        Command::Run {
            scene,
            out,
            duration,
            quiet,
            memory_limit,
        } => run(scene, out, duration, !quiet, memory_limit),
        Command::Check {
            mesh,
            scale,
            young,
            poisson,
            density,
            cells_across,
        } => check(mesh, scale, [young, poisson, density], cells_across),
        Command::Advise {
            scene,
            out,
            target,
            duration,
            quiet,
        } => advise(&scene, out, target, duration, quiet),
        Command::Calibrate => calibrate(),
    };
    match result {
        Ok(()) => ExitCode::SUCCESS,
        Err(message) => {
            eprintln!("error: {message}");
            ExitCode::FAILURE
        }
    }
}

/// `advise`: advises on `scene` for `target` over `duration` (s) into `out`; prints the table.
fn advise(
    scene: &std::path::Path,
    out: PathBuf,
    target: f64,
    duration: Option<f64>,
    quiet: bool,
) -> Result<(), String> {
    let options = advise::AdviseOptions {
        target,
        window: duration,
        out,
    };
    let advice = advise::advise(scene, &options, |line| {
        if !quiet {
            eprintln!("{line}");
        }
    })
    .map_err(|e| e.to_string())?;
    print_advice(&advice);
    Ok(())
}

/// Prints `advice`: each body's needs and alternatives, then the recommendation.
fn print_advice(advice: &advise::Advice) {
    println!(
        "{}: target {:.2} %, {:.3} s per run; as written {:.3} ms per frame (two runs {:.1} % apart)",
        advice.scene_file,
        advice.target * 100.0,
        advice.window_s,
        advice.reference_ms_per_frame,
        advice.reference_spread * 100.0
    );
    let print_alternative = |a: &advise::Alternative| match (a.error, a.ms_per_frame) {
        (Some(error), Some(ms)) => println!(
            "    {:<44} error {:>10} {:>9.3} ms/frame  {}",
            a.label,
            percent(error),
            ms,
            a.verdict
        ),
        _ => println!("    {:<44} {}", a.label, a.verdict),
    };
    for body in &advice.soft_bodies {
        let n = &body.needs;
        // A material without a label is named by its model already.
        let given = match body.material.starts_with(&body.model) {
            true => body.material.clone(),
            false => format!("{} {}", body.material, body.model),
        };
        println!(
            "  {} ({given}, {}): peak strain {:.4}, peak rotation {:.1} deg, pushed by a collider in {} frames",
            body.name, body.elements, n.peak_green_strain, n.peak_rotation_deg, n.contact_frames
        );
        if let Some(error) = body.discretization_error {
            println!(
                "    its discretization error, estimated from the coarser mesh: {}",
                percent(error)
            );
        }
        body.alternatives.iter().for_each(print_alternative);
    }
    println!("  the scene:");
    advice.scene_alternatives.iter().for_each(print_alternative);
    for warning in &advice.warnings {
        println!("  warning: {warning}");
    }
    let r = &advice.recommendation;
    println!(
        "recommended: {}
  error predicted {:.3} %, measured {:.3} % ({}); {:.3} ms per frame predicted, {:.3} measured: {:.2}x faster; {}
  written to {}",
        if r.changes.is_empty() { "the scene as written".to_owned() } else { r.changes.join("; ") },
        r.predicted_error * 100.0,
        r.measured_error * 100.0,
        if r.worst_probe.is_empty() { "-" } else { &r.worst_probe },
        r.predicted_ms_per_frame,
        r.measured_ms_per_frame,
        r.speed_up,
        if r.within_target { "within the target" } else { "NOT within the target" },
        r.file
    );
}

/// A relative error in percent: three decimals, or three significant figures below 0.01 %.
fn percent(error: f64) -> String {
    match error * 100.0 {
        p if p == 0.0 || p >= 0.01 => format!("{p:.3} %"),
        p => format!("{p:.2e} %"),
    }
}

/// `calibrate`: measures the cost model and prints it.
fn calibrate() -> Result<(), String> {
    let cost = rapier_fvm_runner::calibrate::calibrate(|line| eprintln!("{line}"))
        .map_err(|e| e.to_string())?;
    print!("{}", rapier_fvm_runner::calibrate::as_toml(&cost));
    Ok(())
}

/// `run` of a 2D scene (`dimension = 2`): runs it and prints a summary.
fn run_planar(path: PathBuf, text: String, options: &RunOptions) -> Result<(), String> {
    let scene = PlanarScene::parse(&path, text).map_err(|e| e.to_string())?;
    let report = planar::run_planar(&scene, options).map_err(|e| e.to_string())?;
    print_timing(
        &format!("{} (2D)", report.scene),
        report.frames,
        [
            report.simulated_time,
            report.wall_time_s,
            report.stepping_time_s,
        ],
    );
    print_frame_times(&report.frame_times);
    for body in &report.soft_bodies {
        println!(
            "  soft {:<16} {:>6} triangles {:>5} nodes, plane {}, {:.3} kg; {} implicit frames, at most {} explicit substeps per coupling substep; {} failed",
            body.name,
            body.triangles,
            body.nodes,
            body.plane,
            body.mass,
            body.implicit_frames,
            body.max_explicit_substeps,
            body.failed_frames
        );
    }
    for probe in &report.probes {
        println!(
            "  probe {:<24} final {:.6e} {}",
            probe.name, probe.final_value, probe.unit
        );
    }
    println!("  state finite at the end: {}", report.final_state_finite);
    println!("  written to {}", options.out.display());
    Ok(())
}

/// `run`: runs the scene, its soft bodies within `memory_limit` GB if given, and prints a
/// summary.
fn run(
    scene: PathBuf,
    out: PathBuf,
    duration: Option<f64>,
    progress: bool,
    memory_limit: Option<f64>,
) -> Result<(), String> {
    let budget = match memory_limit {
        None => MemoryBudget::available(),
        Some(gb) if gb.is_finite() && gb > 0.0 => MemoryBudget::given(gb * 1e9),
        Some(gb) => {
            return Err(format!(
                "--memory-limit must be a positive, finite number of GB, got {gb}"
            ));
        }
    };
    let options = RunOptions {
        out: out.clone(),
        duration,
        progress: progress && std::io::stderr().is_terminal(),
    };
    if let Ok(text) = std::fs::read_to_string(&scene)
        && dimension_of(&text) == Some(2)
    {
        return run_planar(scene, text, &options);
    }
    let scene = Scene::load_within(&scene, budget).map_err(|e| e.to_string())?;
    let report = sim::run(&scene, &options).map_err(|e| e.to_string())?;
    print_summary(&report, &out);
    Ok(())
}

/// Prints the first line of a run's summary: `label`, the frames, the simulated, wall and
/// stepping times (s), the time per frame and the speed against real time.
fn print_timing(label: &str, frames: usize, [simulated, wall, stepping]: [f64; 3]) {
    println!(
        "{label}: {frames} frames, {simulated:.3} s simulated in {wall:.2} s ({stepping:.2} s stepping, {:.2} ms per frame, {:.2}x real time)",
        stepping * 1e3 / frames.max(1) as f64,
        simulated / stepping.max(1e-9),
    );
}

/// Prints the summary of a 3D run written into `out`.
fn print_summary(report: &sim::Report, out: &std::path::Path) {
    print_timing(
        &report.scene,
        report.frames,
        [
            report.simulated_time,
            report.wall_time_s,
            report.stepping_time_s,
        ],
    );
    print_frame_times(&report.frame_times);
    for body in &report.soft_bodies {
        print_soft_body(body);
    }
    for probe in &report.probes {
        println!(
            "  probe {:<28} final {:>12.5e} {}",
            probe.name, probe.final_value, probe.unit
        );
    }
    let s = &report.stability;
    println!(
        "  stability: {}; non-finite {}, errors {}, inverted elements {}, final state finite {}, system energy gained {}",
        if s.stable { "stable" } else { "NOT STABLE" },
        s.non_finite,
        s.any_error,
        s.inverted_elements,
        s.final_state_finite,
        flag(s.system_energy_gained.as_ref())
    );
    for body in report.soft_bodies.iter().filter(|b| !b.stable) {
        let f = &body.stability_flags;
        println!(
            "  {} not stable: energy gained {}, penetration {}, crossing {}, inverted {}, collapsed {}, refused frames {}{}",
            body.name,
            flag(f.energy_gained.as_ref()),
            flag(f.penetration.as_ref()),
            flag(f.crossing.as_ref()),
            flag(f.inverted_elements.as_ref()),
            flag(f.collapsed_elements.as_ref()),
            body.failed_frames,
            body.first_error
                .as_ref()
                .map_or(String::new(), |e| format!(" (first: {e})"))
        );
    }
    println!("  written to {}", out.display());
}

/// Prints where a run's stepping time went: the median and slowest frames, the frames slower
/// than real time with their share of the stepping, and (3D) the parts of the stepping.
fn print_frame_times(times: &sim::FrameTimes) {
    println!(
        "  frames: median {:.2} ms, slowest {:.2} ms (frame {}); {} of {} over the real-time budget of {:.2} ms, {:.0} % of the stepping",
        times.median_ms,
        times.slowest_ms,
        times.slowest_frame,
        times.over_budget_frames,
        times.ms.len(),
        times.budget_ms,
        100.0 * times.over_budget_share,
    );
    if let Some(parts) = &times.parts {
        println!(
            "  time: soft steps {:.2} s over the threads (implicit {:.2} s with dynamic rigid partners, {:.2} s without; explicit {:.2} s with, {:.2} s without), contact detection {:.2} s, rapier {:.2} s",
            parts.soft_steps_s,
            parts.implicit_with_rigid_partners_s,
            parts.implicit_without_rigid_partners_s,
            parts.explicit_with_rigid_partners_s,
            parts.explicit_without_rigid_partners_s,
            parts.contact_detection_s,
            parts.rapier_steps_s,
        );
    }
}

/// Prints a 3D soft body's line of the summary: its elements, frames, failures and the cost
/// of its steps.
fn print_soft_body(body: &sim::SoftBodyReport) {
    let embedded = body
        .embedded_tets
        .map_or(String::new(), |tets| format!(", carrying {tets} tets"));
    println!(
        "  soft {:<16} {:>6} {} {:>5} nodes{embedded}; {} explicit / {} implicit / {} asleep / {} rigid frames; {} failed; max inverted {}",
        body.name,
        body.elements,
        body.element_kind,
        body.nodes,
        body.explicit_frames,
        body.implicit_frames,
        body.asleep_frames,
        body.rigid_frames,
        body.failed_frames,
        body.max_inverted_elements
    );
    let c = &body.cost;
    println!(
        "       {:<16} per step: predicted explicit {:.3} ms, implicit {:.3} ms; used {:.3} ms predicted, {:.3} ms measured ({:.2}x; explicit steps {:.2}x, median {:.2}x; implicit {:.2}x, median {:.2}x)",
        "",
        c.predicted_explicit_ms,
        c.predicted_implicit_ms,
        c.predicted_ms,
        c.measured_ms,
        c.measured_over_predicted,
        c.explicit.measured_over_predicted,
        c.explicit.median_measured_over_predicted,
        c.implicit.measured_over_predicted,
        c.implicit.median_measured_over_predicted,
    );
    if c.implicit.steps > 0 {
        let w = &c.implicit_work;
        println!(
            "       {:<16} implicit step: {:.2} Newton iterations, {:.2} factorizations, {:.2} energy evaluations",
            "", w.newton_iterations, w.factorizations, w.energy_evaluations
        );
    }
}

/// A flag as the summary prints it: `-` when never raised, else its first frame, frame count and
/// worst value.
fn flag(flag: Option<&rapier_fvm_runner::sim::Flag>) -> String {
    flag.map_or(String::from("-"), |f| {
        format!(
            "from frame {} in {} frames, worst {:.3e} {}",
            f.first_frame, f.frames, f.worst, f.unit
        )
    })
}

/// `check`: prints the mesh's quality report and its regions (Gmsh physical groups).
fn check(
    mesh: PathBuf,
    scale: f64,
    [young, poisson, density]: [f64; 3],
    cells_across: usize,
) -> Result<(), String> {
    let material = Material::new(MaterialModel::StableNeoHookean, young, poisson, density)
        .map_err(|e| e.to_string())?;
    if !(2..=128).contains(&cells_across) {
        return Err(format!(
            "--cells-across must lie in 2 to 128, got {cells_across}"
        ));
    }
    let mut raw = import::load_raw(&mesh, scale, &SurfaceOptions { cells_across })
        .map_err(|e| e.to_string())?;
    let r = import::check_raw(&raw);
    let quadratic = !raw.mid_edge_nodes.is_empty();
    let hexahedra = match raw.hexahedra {
        import::Hexahedra::None => None,
        import::Hexahedra::Linear(_) => Some("linear"),
        import::Hexahedra::Triquadratic(_) => Some("27-node"),
    };
    let regions = std::mem::take(&mut raw.regions);
    // The time steps need a mesh a body can be built of: no invalid or degenerate element. They
    // are those of the linear tetrahedra on the corners (mid-edge nodes of quadratic ones unused).
    let corners = import::RawMesh {
        mid_edge_nodes: Vec::new(),
        ..raw
    };
    let steps = (r.invalid == 0 && r.degenerate == 0 && r.folded == 0)
        .then(|| corners.into_mesh().ok())
        .flatten()
        .and_then(|mesh| SymplecticEuler::mesh_time_steps(mesh, &material).ok());
    let step =
        |s: Option<f64>| s.map_or_else(|| "- (mesh unusable)".to_owned(), |s| format!("{s:.4e} s"));
    println!("{}", mesh.display());
    if let Some(kind) = hexahedra {
        println!(
            "  hexahedra           {} ({kind}), split into {} tetrahedra",
            r.hexahedra, r.tets
        );
    } else {
        let order = if quadratic { "quadratic" } else { "linear" };
        println!("  tetrahedra          {} ({order})", r.tets);
    }
    println!(
        "  nodes               {} ({} unused)",
        r.nodes, r.unused_nodes
    );
    println!("  volume              {:.6e} m³", r.volume);
    let corners_only = if quadratic {
        " (corner tetrahedra)"
    } else if hexahedra.is_some() {
        " (their tetrahedra)"
    } else {
        ""
    };
    println!(
        "  dihedral angles     {:.2}° to {:.2}°{corners_only}",
        r.min_dihedral_angle, r.max_dihedral_angle
    );
    println!(
        "  min radius ratio    {:.4}{corners_only}",
        r.min_radius_ratio
    );
    println!("  inverted            {}", r.inverted);
    println!("  degenerate          {}", r.degenerate);
    println!("  invalid             {}", r.invalid);
    if quadratic || hexahedra == Some("27-node") {
        println!("  folded              {}", r.folded);
    }
    for region in &regions {
        let tets = if region.tets.is_empty() {
            String::new()
        } else {
            format!(", {} tetrahedra", region.tets.len())
        };
        println!(
            "  region              {region}: {} nodes{tets}",
            region.nodes.len()
        );
    }
    println!("  material            E = {young:e} Pa, nu = {poisson}, rho = {density} kg/m³");
    println!("  critical time step  {}", step(steps.map(|s| s.critical)));
    println!("  stable time step    {}", step(steps.map(|s| s.stable)));
    Ok(())
}
