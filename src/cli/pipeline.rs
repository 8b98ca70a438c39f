//! `perturbid run PIPELINE.toml`: a whole pipeline (plan, simulate, identify, validate, ...)
//! from one configuration file, step after step. Each step is one of the subcommands, its
//! arguments written as TOML keys named as the command line's (`max_evaluations` or
//! `max-evaluations` for `--max-evaluations`; `robot`, `log`, ... for the positional ones), so
//! a pipeline means exactly what the same commands typed by hand mean and is checked by the
//! same parser. Relative paths are relative to the pipeline file. See docs/pipeline.md.

use std::collections::BTreeMap;
use std::fmt::Write as _;
use std::path::{Path, PathBuf};

use clap::{ArgAction, CommandFactory, Parser};
use serde::Deserialize;
use toml::{Spanned, Value};

use super::clap_message;
use crate::error::{Error, Result};
use crate::io::config::{location, read_toml};

#[derive(clap::Args)]
pub(crate) struct RunArgs {
    /// The pipeline: a TOML file with `[defaults]` (keys given to every step that takes them)
    /// and `[[step]]` tables (`run = "identify-direct"` and that command's arguments).
    pipeline: PathBuf,
    /// Print the commands the pipeline runs, one per line, and stop.
    #[arg(long)]
    dry_run: bool,
}

/// The file: shared keys and the steps in order.
#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct Pipeline {
    #[serde(default)]
    defaults: BTreeMap<String, Spanned<Value>>,
    step: Vec<Spanned<BTreeMap<String, Spanned<Value>>>>,
}

/// At most this many steps: a pipeline is written by hand.
const MAX_STEPS: usize = 1000;

/// One step as command-line arguments (after the program name).
struct Step {
    command: String,
    args: Vec<String>,
    /// Where the step starts in the file, for messages.
    at: String,
}

pub(crate) fn run(a: RunArgs) -> Result<String> {
    let source = a.pipeline.display().to_string();
    let (pipeline, text): (Pipeline, String) = read_toml(&a.pipeline)?;
    let base = a
        .pipeline
        .parent()
        .filter(|p| !p.as_os_str().is_empty())
        .unwrap_or(Path::new("."))
        .to_path_buf();
    let steps = steps(&pipeline, &source, &text, &base)?;
    if a.dry_run {
        let mut out = String::new();
        for s in &steps {
            let words: Vec<String> = std::iter::once("perturbid".to_string())
                .chain(std::iter::once(s.command.clone()))
                .chain(s.args.iter().cloned())
                .map(|w| shell_quote(&w))
                .collect();
            let _ = writeln!(out, "{}", words.join(" "));
        }
        return Ok(out);
    }
    let mut out = String::new();
    for (k, s) in steps.iter().enumerate() {
        let argv = std::iter::once("perturbid".to_string())
            .chain(std::iter::once(s.command.clone()))
            .chain(s.args.iter().cloned());
        // checked in `steps`: every step parses
        let cli = super::Cli::try_parse_from(argv).map_err(|e| Error::Config {
            location: s.at.clone(),
            message: clap_message(&e),
        })?;
        let _ = writeln!(out, "== step {}/{}: {} ==", k + 1, steps.len(), s.command);
        let text = super::run(cli).map_err(|e| match e {
            Error::Interrupted { .. } => e,
            e => Error::Config {
                location: format!("{} ({})", s.at, s.command),
                message: format!(
                    "{e}{}",
                    if k > 0 {
                        format!("; steps 1-{k} finished and their outputs stand")
                    } else {
                        String::new()
                    }
                ),
            },
        })?;
        out.push_str(&text);
        if !text.ends_with('\n') {
            out.push('\n');
        }
    }
    Ok(out)
}

/// The steps as argument lists, every one checked by the command line's parser before any
/// runs: a mistake in step 5 is found before step 1 spends an hour.
fn steps(p: &Pipeline, source: &str, text: &str, base: &Path) -> Result<Vec<Step>> {
    if p.step.is_empty() {
        return Err(Error::Config {
            location: source.into(),
            message: "no [[step]]: nothing to run".into(),
        });
    }
    if p.step.len() > MAX_STEPS {
        return Err(Error::Config {
            location: source.into(),
            message: format!("{} steps, at most {MAX_STEPS} allowed", p.step.len()),
        });
    }
    let mut root = super::Cli::command();
    root.build(); // positional indices are assigned here
    let mut used_defaults = std::collections::BTreeSet::new();
    let mut out = Vec::new();
    for (k, step) in p.step.iter().enumerate() {
        let at = format!(
            "{}, step {}",
            location(source, text, step.span().start),
            k + 1
        );
        let keys = step.get_ref();
        let (command, sub) = step_command(&root, keys, source, text, &at)?;
        let mut positional: Vec<(usize, Vec<String>)> = Vec::new();
        let mut options: Vec<String> = Vec::new();
        let mut given = std::collections::BTreeSet::new();
        let own = keys.iter().filter(|(key, _)| key.as_str() != "run");
        let shared = p
            .defaults
            .iter()
            .filter(|(key, _)| !keys.contains_key(key.as_str()));
        for (from_default, (key, value)) in
            own.map(|kv| (false, kv)).chain(shared.map(|kv| (true, kv)))
        {
            let canonical = key.replace('-', "_");
            let arg = sub.get_arguments().find(|a| {
                a.get_id().as_str() == canonical
                    || a.get_long()
                        .is_some_and(|l| l.replace('-', "_") == canonical)
            });
            let Some(arg) = arg else {
                if from_default {
                    continue; // a default for other steps
                }
                let known: Vec<String> = sub
                    .get_arguments()
                    .filter(|a| !matches!(a.get_id().as_str(), "help" | "version"))
                    .map(|a| {
                        a.get_long()
                            .map_or(a.get_id().to_string(), |l| l.replace('-', "_"))
                    })
                    .collect();
                return Err(Error::Config {
                    location: location(source, text, value.span().start),
                    message: format!(
                        "'{key}' is not an argument of '{command}'; it takes: {}",
                        known.join(", ")
                    ),
                });
            };
            if !given.insert(arg.get_id().to_string()) {
                return Err(Error::Config {
                    location: location(source, text, value.span().start),
                    message: format!("'{key}' is given twice (as '-' and '_' spellings)"),
                });
            }
            if from_default {
                used_defaults.insert(key.clone());
            }
            let at_value = location(source, text, value.span().start);
            let words = words(key, value.get_ref(), arg, base, &at_value)?;
            if arg.is_positional() {
                positional.push((arg.get_index().unwrap_or(usize::MAX), words));
            } else {
                let long = arg.get_long().unwrap_or(key.as_str()).to_string();
                match arg.get_action() {
                    ArgAction::SetTrue | ArgAction::SetFalse => {
                        if words.first().is_some_and(|w| w == "true") {
                            options.push(format!("--{long}"));
                        }
                    }
                    _ => {
                        for w in words {
                            options.push(format!("--{long}={w}"));
                        }
                    }
                }
            }
        }
        positional.sort_by_key(|(i, _)| *i);
        let mut args = options;
        if !positional.is_empty() {
            args.push("--".into());
            args.extend(positional.into_iter().flat_map(|(_, w)| w));
        }
        let argv = ["perturbid".to_string(), command.clone()]
            .into_iter()
            .chain(args.iter().cloned());
        if let Err(e) = super::Cli::try_parse_from(argv) {
            return Err(Error::Config {
                location: at,
                message: clap_message(&e),
            });
        }
        out.push(Step {
            command: command.clone(),
            args,
            at,
        });
    }
    if let Some((key, v)) = p
        .defaults
        .iter()
        .find(|(key, _)| !used_defaults.contains(key.as_str()))
    {
        return Err(Error::Config {
            location: location(source, text, v.span().start),
            message: format!("default '{key}' is taken by no step"),
        });
    }
    Ok(out)
}

/// The command a step's `run` key names, among those a pipeline can run (not `run` itself).
fn step_command<'c, 'k>(
    root: &'c clap::Command,
    keys: &'k std::collections::BTreeMap<String, toml::Spanned<Value>>,
    source: &str,
    text: &str,
    at: &str,
) -> Result<(&'k String, &'c clap::Command)> {
    let Some(run) = keys.get("run") else {
        return Err(Error::Config {
            location: at.into(),
            message:
                "no 'run' key: say which command the step runs, e.g. run = \"identify-direct\""
                    .into(),
        });
    };
    let Value::String(command) = run.get_ref() else {
        return Err(Error::Config {
            location: location(source, text, run.span().start),
            message: "'run' must be a command name in quotes".into(),
        });
    };
    let names: Vec<&str> = root
        .get_subcommands()
        .map(|c| c.get_name())
        .filter(|n| *n != "run")
        .collect();
    let Some(sub) = root
        .get_subcommands()
        .find(|c| c.get_name() == command && command != "run")
    else {
        return Err(Error::Config {
            location: location(source, text, run.span().start),
            message: format!(
                "'{command}' is not a command a pipeline can run; expected one of: {}",
                names.join(", ")
            ),
        });
    };
    Ok((command, sub))
}

/// The command-line words of one TOML value for `arg`: a scalar gives one, a list one per
/// element (for arguments that repeat), `lock = { joint = value }` one `JOINT=VALUE` per
/// joint. Relative paths are made relative to the pipeline's folder.
fn words(key: &str, value: &Value, arg: &clap::Arg, base: &Path, at: &str) -> Result<Vec<String>> {
    let bad = |message: String| Error::Config {
        location: at.into(),
        message,
    };
    let flag = matches!(arg.get_action(), ArgAction::SetTrue | ArgAction::SetFalse);
    let many = matches!(arg.get_action(), ArgAction::Append)
        || arg.get_num_args().is_some_and(|n| n.max_values() > 1);
    // `op = { q = [...], qd = [...], qdd = [...] }`: the operating point written out, and
    // `payload = { link = "link6", mass = 2.0, ... }` a payload (or a list of them), given as
    // their JSON
    let written_out = ["op", "payload"].contains(&arg.get_id().as_str());
    let table_json = |t: &toml::Table| -> Result<String> {
        serde_json::to_string(t).map_err(|e| bad(format!("'{key}': {e}")))
    };
    let scalar = |v: &Value| -> Result<String> {
        match v {
            Value::String(s) => Ok(s.clone()),
            Value::Integer(i) => Ok(i.to_string()),
            // whole numbers as integers (a count written 2.0), others short (1e-320, not 320
            // digits): both read back exactly
            Value::Float(f) if f.is_finite() && f.fract() == 0.0 && f.abs() < 1e15 => {
                Ok(format!("{f}"))
            }
            Value::Float(f) if f.is_finite() => Ok(crate::error::shown(*f)),
            Value::Float(f) => Err(bad(format!("'{key}' is {f}, expected a finite number"))),
            Value::Boolean(b) if flag => Ok(b.to_string()),
            Value::Boolean(_) => Err(bad(format!("'{key}' takes a value, not true/false"))),
            other => Err(bad(format!(
                "'{key}' is a {}, expected a string or a number",
                other.type_str()
            ))),
        }
    };
    let mut words = match value {
        Value::Boolean(_) if !flag => {
            return Err(bad(format!("'{key}' takes a value, not true/false")))
        }
        Value::Boolean(b) => return Ok(vec![b.to_string()]),
        _ if flag => return Err(bad(format!("'{key}' is a switch: write {key} = true"))),
        Value::Array(items) if many => (items.iter())
            .map(|v| match v {
                Value::Table(t) if written_out => table_json(t),
                v => scalar(v),
            })
            .collect::<Result<Vec<_>>>()?,
        Value::Array(_) => return Err(bad(format!("'{key}' takes one value, not a list"))),
        Value::Table(t)
            if many
                && arg.get_value_names().is_some_and(|n| {
                    n.iter()
                        .any(|n| ["JOINT=VALUE", "TARGET=SOURCE[*SCALE]"].contains(&n.as_str()))
                }) =>
        {
            // `lock = { joint = value }`, `column = { t = "timestamp*ms" }`
            t.iter()
                .map(|(joint, v)| Ok(format!("{joint}={}", scalar(v)?)))
                .collect::<Result<Vec<_>>>()?
        }
        Value::Table(t) if written_out => return Ok(vec![table_json(t)?]),
        v => vec![scalar(v)?],
    };
    for w in &mut words {
        *w = resolve(w, arg, base);
    }
    Ok(words)
}

/// A path relative to the pipeline's folder, for arguments that name files: those whose value
/// is a path, and the robot when such a file exists (otherwise it is a built-in name).
fn resolve(word: &str, arg: &clap::Arg, base: &Path) -> String {
    let p = Path::new(word);
    if p.is_absolute()
        || word.is_empty()
        || (super::files::is_inline_json(p) && !base.join(p).exists())
    {
        return word.to_string();
    }
    let is_path = matches!(
        arg.get_value_hint(),
        clap::ValueHint::AnyPath | clap::ValueHint::FilePath | clap::ValueHint::DirPath
    );
    let is_robot = arg.get_id().as_str() == "robot" && base.join(p).is_file();
    if is_path || is_robot {
        base.join(p).display().to_string()
    } else {
        word.to_string()
    }
}

/// `word` quoted for a POSIX shell when it needs to be.
fn shell_quote(word: &str) -> String {
    let plain = !word.is_empty()
        && word
            .chars()
            .all(|c| c.is_ascii_alphanumeric() || "-_./=:,+@%".contains(c));
    if plain {
        word.to_string()
    } else {
        format!("'{}'", word.replace('\'', "'\\''"))
    }
}
