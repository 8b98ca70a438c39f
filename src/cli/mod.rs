//! The `perturbid` command line: the same program whether built with cargo (`src/bin`) or
//! installed by pip (a console script calling [`main_with_args`] through the extension module).

mod columns;
mod direct;
mod files;
mod gains;
mod info;
mod local;
mod paper;
mod parameters;
mod payload;
mod pipeline;
mod progress;
mod session;
mod study;
mod urdf;
mod validate;

use std::ffi::OsString;
use std::path::PathBuf;

use clap::{Parser, Subcommand};

use crate::error::Result;

#[derive(Parser)]
#[command(
    name = "perturbid",
    version,
    about = "Robot dynamics identification about an operating point (Kinsheel & Taha 2010) and by the direct method",
    after_help = "ROBOT is a URDF file or a built-in robot: a465 (= a465:kinsheel2010), a465:physical.\n\
CSV files have a header: t, q1..qN, optional qd1..qN and qdd1..qN, tau1..tauN (or q_<joint>, qd_<joint>, ... named after the URDF's joints)."
)]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Subcommand)]
enum Command {
    /// Print a robot's joints, limits and masses.
    Info(info::InfoArgs),
    /// Plan the experiments at an operating point: writes plan.json and one trajectory CSV per
    /// experiment (t, q, qd, qdd) for the robot controller.
    Plan(local::PlanArgs),
    /// Simulate what the robot would log running a plan: one recording CSV per experiment.
    Simulate(local::SimulateArgs),
    /// Split one log of a whole session (the plan's experiments run one after the other, with
    /// moves and pauses between them) into one recording CSV per experiment for `identify`.
    Split(session::SplitArgs),
    /// Identify the local model from a plan and its recordings; writes the model (JSON) and
    /// prints T*, D*, H*, G* with condition numbers and standard errors.
    Identify(local::IdentifyArgs),
    /// Design a Fourier excitation for the direct method (COBYLA): writes excitation.json and
    /// the sampled trajectory CSV.
    Excite(direct::ExciteArgs),
    /// How a log's columns are read as a recording's (with --column and --ignore-columns, as
    /// every command that reads a log takes them): each column read with its source and scale,
    /// those left out; refused as those commands would refuse it.
    Columns(columns::ColumnsArgs),
    /// Identify base parameters (the direct method) from a recording CSV; writes the model
    /// (JSON) and prints the fit.
    IdentifyDirect(direct::IdentifyDirectArgs),
    /// Identify the joints' drive gains with the base parameters from logs of motor currents,
    /// some with a known payload bolted on; writes the base-parameter model with the gains
    /// (JSON) and prints the gains.
    IdentifyGains(gains::IdentifyGainsArgs),
    /// Identify a payload's mass, centre of mass and inertia from a log of the robot carrying
    /// it, against a model of the robot alone (identify-direct) or its URDF: writes
    /// payload.json (as identify-gains --payload reads it) and payload_fit.json.
    IdentifyPayload(payload::IdentifyPayloadArgs),
    /// The robot as URDF (a built-in robot's own file), with a payload attached as a link of
    /// its own where --payload gives one (payload.json of identify-payload).
    Urdf(urdf::UrdfArgs),
    /// Torques predicted by a saved model (local or base-parameter) at the states of a CSV.
    Predict(direct::PredictArgs),
    /// A saved model against a log (positions and torques; preprocessed as for
    /// identification): writes residuals.csv, validation.json and validation.svg, and prints
    /// per joint the RMS, relative RMS and largest error.
    Validate(validate::ValidateArgs),
    /// The robot's base parameters from local models at one or more operating points: writes
    /// a base-parameter model (JSON) and says which parameters the points leave unidentified.
    Parameters(parameters::ParametersArgs),
    /// Reproduce the paper (Tables 2 and 3, Figs. 3-5) on the built-in A465: report.md, CSV,
    /// JSON and SVG figures in --out.
    Paper(paper::PaperArgs),
    /// Run a whole pipeline from one TOML file: its steps are the commands above, their
    /// arguments written as keys (docs/pipeline.md); every step is checked before the first
    /// runs.
    Run(pipeline::RunArgs),
    /// A study of when the local model beats the global one, over robots, operating points,
    /// true robots, noise, designs and seeds (docs/study.md): tidy results, summaries with
    /// intervals and a figure in --out; resumable; every core.
    Study(study::StudyArgs),
}

/// Where a subcommand writes: a folder or a file.
pub(crate) fn out_dir(out: &Option<PathBuf>) -> PathBuf {
    out.clone().unwrap_or_else(|| PathBuf::from("."))
}

fn run(cli: Cli) -> Result<String> {
    match cli.command {
        Command::Info(a) => info::run(a),
        Command::Urdf(a) => urdf::run(a),
        Command::Plan(a) => local::plan(a),
        Command::Simulate(a) => local::simulate(a),
        Command::Split(a) => session::split(a),
        Command::Identify(a) => local::identify(a),
        Command::Excite(a) => direct::excite(a),
        Command::Columns(a) => columns::run(a),
        Command::IdentifyDirect(a) => direct::identify_direct(a),
        Command::IdentifyGains(a) => gains::identify_gains(a),
        Command::IdentifyPayload(a) => payload::run(a),
        Command::Predict(a) => direct::predict(a),
        Command::Parameters(a) => parameters::run(a),
        Command::Validate(a) => validate::run(a),
        Command::Paper(a) => paper::run(a),
        Command::Run(a) => pipeline::run(a),
        Command::Study(a) => study::run(a),
    }
}

/// clap's error in one line: its first paragraph, without the "error: " prefix.
fn clap_message(e: &clap::Error) -> String {
    let text = e.render().to_string();
    let lines: Vec<&str> = text
        .lines()
        .take_while(|l| !l.trim().is_empty())
        .map(str::trim)
        .collect();
    let line = lines.join(" ");
    line.strip_prefix("error: ").unwrap_or(&line).to_string()
}

/// Runs the command line with `args` (the program name first); prints results on stdout and
/// a one-line error on stderr; returns the exit status (0 on success, 1 on an error, 2 on a
/// usage error, [`EXIT_INTERNAL`] on a bug caught at the boundary).
pub fn main_with_args<I, T>(args: I) -> i32
where
    I: IntoIterator<Item = T>,
    T: Into<OsString> + Clone,
{
    // A bug must still end in one line and a non-zero status: the panic is caught here and
    // reported once (the default hook's message and backtrace are held back meanwhile).
    crate::interrupt::reset();
    let hook = std::panic::take_hook();
    std::panic::set_hook(Box::new(|_| {}));
    let result = crate::error::catch_panics("perturbid", || Ok(main_unguarded(args)));
    std::panic::set_hook(hook);
    result.unwrap_or_else(|e| {
        eprintln!("perturbid: {e}");
        EXIT_INTERNAL
    })
}

/// Exit status of a bug caught at the boundary (`EX_SOFTWARE` of sysexits.h).
pub const EXIT_INTERNAL: i32 = 70;
/// Exit status after Ctrl-C (128 + SIGINT, as shells report it).
pub const EXIT_INTERRUPTED: i32 = 130;

fn main_unguarded<I, T>(args: I) -> i32
where
    I: IntoIterator<Item = T>,
    T: Into<OsString> + Clone,
{
    let cli = match Cli::try_parse_from(args) {
        Ok(c) => c,
        Err(e) => {
            use clap::error::ErrorKind as Kind;
            let code = e.exit_code();
            if matches!(e.kind(), Kind::DisplayHelp | Kind::DisplayVersion)
                || matches!(e.kind(), Kind::DisplayHelpOnMissingArgumentOrSubcommand)
            {
                let _ = e.print();
                return code;
            }
            // a usage error in one line, like every other error, and where to read more
            eprintln!("perturbid: {} (see perturbid --help)", clap_message(&e));
            return code;
        }
    };
    match run(cli) {
        Ok(text) => {
            // A closed pipe (`perturbid info a465 | head`) is not an error worth a panic.
            let _ = std::io::Write::write_all(&mut std::io::stdout().lock(), text.as_bytes());
            0
        }
        Err(e) if e.kind() == crate::error::ErrorKind::Interrupted => {
            // a study keeps what finished (it says so); other work writes nothing on Ctrl-C
            if e.to_string().contains("the same command resumes") {
                eprintln!("perturbid: {e}");
            } else {
                eprintln!("perturbid: {e}; nothing was written");
            }
            EXIT_INTERRUPTED
        }
        Err(e) => {
            eprintln!("perturbid: {e}");
            1
        }
    }
}
