//! The scenes contract: `cargo run --release --example <scene> -- [--set
//! name=value]... [--out DIR]`. Output goes to `out/<scene>/` by default:
//! PNG (and SVG) figures, CSV data and `summary.json`. A scene's files are
//! written into a hidden staging folder beside the output folder, which
//! replaces the output folder as a whole when `summary.json` is written (the
//! scene's last step): a crash never leaves half-written files or a mix of
//! old and new results.

use mechlab_runtime::settings::{Range, SettingValue};
use std::borrow::Cow;
use std::io::Write;
use std::path::{Path, PathBuf};

/// A knob of a scene: name, default (as text) and help; a declared
/// analysis's knobs are made from its declaration
/// ([`Knob::from_declaration`]).
#[derive(Clone, Debug)]
pub struct Knob {
    pub name: &'static str,
    pub default: Cow<'static, str>,
    pub help: Cow<'static, str>,
}

pub const fn knob(name: &'static str, default: &'static str, help: &'static str) -> Knob {
    Knob {
        name,
        default: Cow::Borrowed(default),
        help: Cow::Borrowed(help),
    }
}

impl Knob {
    /// The knob of a declared setting, its range in the help.
    pub fn from_declaration(d: mechlab_runtime::settings::Declaration) -> Knob {
        let help = match d.range.as_str() {
            "any" => format!("{} [{}]", d.help, d.kind),
            range => format!("{} [{}, {range}]", d.help, d.kind),
        };
        Knob {
            name: d.name,
            default: Cow::Owned(d.default_text),
            help: Cow::Owned(help),
        }
    }
}

impl Drop for Scene {
    /// An unpublished staging folder (the scene failed) is removed.
    fn drop(&mut self) {
        let _ = std::fs::remove_dir_all(&self.staging);
    }
}

/// Knobs for every parameter of a generated model, with the defaults of its
/// model file except those `overrides` gives.
pub fn parameter_knobs(
    info: &'static mechlab_runtime::registry::ModelInfo,
    overrides: &[(&'static str, &'static str)],
) -> Vec<Knob> {
    info.parameter_names
        .iter()
        .zip(info.parameter_defaults)
        .zip(info.parameter_descriptions)
        .map(|((&name, &default), &help)| {
            let default = overrides
                .iter()
                .find(|(n, _)| *n == name)
                .map_or(default, |(_, v)| v);
            knob(name, default, help)
        })
        .collect()
}

/// What is wrong with a `--set` value.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum ValueProblem {
    /// A requirement the value failed, as the knob states it.
    #[error("{0}")]
    Requirement(&'static str),
    /// Not of the knob's kind or outside its range.
    #[error("takes {kind}, {range}")]
    Kind { kind: &'static str, range: String },
}

/// Why a scene could not run.
#[derive(Debug, thiserror::Error)]
pub enum SceneError {
    #[error("{flag} needs a value")]
    MissingValue { flag: String },
    #[error("--set {pair}: expected name=value")]
    NotAPair { pair: String },
    #[error("--set {knob}: unknown knob for scene {scene} (known: {})", known.join(", "))]
    UnknownKnob {
        knob: String,
        scene: &'static str,
        known: Vec<&'static str>,
    },
    #[error("unexpected argument '{argument}' (see --help)")]
    UnexpectedArgument { argument: String },
    /// Knob values that are each valid but do not fit together.
    #[error("{knobs}: {reason}")]
    Inconsistent {
        knobs: &'static str,
        reason: &'static str,
    },
    /// A `--set` value that does not parse or is out of range.
    #[error("--set {name}={value}: {reason}")]
    BadValue {
        name: String,
        value: String,
        reason: ValueProblem,
    },
    /// A computed result against an independent one (a benchmark's check
    /// before it times them): `what` at the state `at`.
    #[error("{what} at {at:?}: {got:?}, but the independent form gives {expected:?}")]
    Disagreement {
        what: String,
        at: Vec<f64>,
        got: Vec<f64>,
        expected: Vec<f64>,
    },
    #[error("{}: {source}", path.display())]
    Io {
        path: PathBuf,
        source: std::io::Error,
    },
    /// A declared setting's value refused (its name, value and range).
    #[error(transparent)]
    Setting(#[from] mechlab_runtime::settings::SettingError),
    #[error(transparent)]
    Analysis(#[from] mechlab_runtime::analysis::declared::AnalysisError),
    #[error(transparent)]
    Ode(#[from] mechlab_runtime::ode::OdeError),
    #[error(transparent)]
    Basins(#[from] mechlab_runtime::analysis::basins::BasinsError),
    #[error(transparent)]
    Contact(#[from] mechlab_runtime::contact::ContactError),
    #[error(transparent)]
    Parameter(#[from] mechlab_runtime::registry::ParameterError),
    #[error(transparent)]
    UnknownModel(#[from] mechlab_runtime::registry::UnknownModel),
    #[error(transparent)]
    Study(#[from] mechlab_runtime::study::StudyError),
    #[error(transparent)]
    Explore(#[from] mechlab_runtime::explore::ExploreError),
    #[error(transparent)]
    Stability(#[from] mechlab_runtime::analysis::stability::StabilityError),
    #[error(transparent)]
    Averaging(#[from] mechlab_runtime::analysis::averaging::AveragingError),
    #[error(transparent)]
    PeriodMap(#[from] mechlab_runtime::analysis::period_map::PeriodMapError),
    #[error(transparent)]
    Splitting(#[from] mechlab_runtime::analysis::separatrix::SplittingError),
    #[error(transparent)]
    Attractor(#[from] mechlab_runtime::analysis::attractor::AttractorError),
    #[error(transparent)]
    Section(#[from] mechlab_runtime::analysis::section::SectionError),
    #[error(transparent)]
    Continuation(#[from] mechlab_runtime::analysis::continuation::ContinuationError),
    #[error(transparent)]
    Constrained(#[from] mechlab_runtime::analysis::on_constraints::ConstrainedError),
    #[error(transparent)]
    Vibration(#[from] mechlab_runtime::analysis::on_constraints::vibration::VibrationError),
    /// The studio's server could not listen, or stopped.
    #[error("the studio cannot serve on {address}: {source}")]
    Serve {
        address: std::net::SocketAddr,
        source: std::io::Error,
    },
    /// Another scene, run by this one, could not start or failed.
    #[error("cannot run scene {scene}: {source}")]
    Spawn {
        scene: String,
        source: std::io::Error,
    },
    #[error("scene {scene} failed ({status})")]
    SceneFailed {
        scene: String,
        status: std::process::ExitStatus,
    },
    /// Links of a written page to files that do not exist.
    #[error("the page links files that do not exist: {0:?}")]
    BrokenLinks(Vec<String>),
    /// A summary that does not serialise (a non-string map key, ...).
    #[error("summary of scene {scene}: {source}")]
    Summary {
        scene: &'static str,
        source: serde_json::Error,
    },
}

/// A parsed command line of a scene.
#[derive(Debug)]
pub struct Scene {
    pub name: &'static str,
    knobs: Vec<Knob>,
    values: Vec<(String, String)>,
    pub out: PathBuf,
    /// Where files are written until `write_summary` publishes them.
    staging: PathBuf,
}

/// With this variable set, a scene checks its arguments (the example, the
/// model, every knob's name) and exits without running: the test of the
/// commands shown in the docs runs them so.
pub const CHECK_ARGUMENTS: &str = "MECHLAB_CHECK_ARGUMENTS";

impl Scene {
    /// Parses `std::env::args`; prints help and exits on `--help`.
    pub fn from_args(name: &'static str, about: &str, knobs: &[Knob]) -> Result<Scene, SceneError> {
        let args: Vec<String> = std::env::args().skip(1).collect();
        if args.iter().any(|a| a == "--help" || a == "-h") {
            println!("{}", Self::help(name, about, knobs));
            std::process::exit(0);
        }
        let scene = Self::parse(name, knobs, &args)?;
        if std::env::var_os(CHECK_ARGUMENTS).is_some() {
            println!("{name}: arguments accepted");
            std::process::exit(0);
        }
        Ok(scene)
    }

    pub fn help(name: &str, about: &str, knobs: &[Knob]) -> String {
        let mut s = format!(
            "{name}: {about}\n\nusage: cargo run --release --example {name} -- [--set name=value]... [--out DIR]\n\nknobs (default):\n"
        );
        for k in knobs {
            s += &format!("  {:<12} ({}) {}\n", k.name, k.default, k.help);
        }
        s += &format!(
            "\noutput: out/{name}/ unless --out is given: PNG figures, CSV data, summary.json\n"
        );
        s
    }

    /// Parses arguments (without the program name).
    pub fn parse(name: &'static str, knobs: &[Knob], args: &[String]) -> Result<Scene, SceneError> {
        let mut values: Vec<(String, String)> = knobs
            .iter()
            .map(|k| (k.name.to_string(), k.default.to_string()))
            .collect();
        let mut out = PathBuf::from("out").join(name);
        let mut i = 0;
        while i < args.len() {
            let next = || {
                args.get(i + 1)
                    .cloned()
                    .ok_or_else(|| SceneError::MissingValue {
                        flag: args[i].clone(),
                    })
            };
            match args[i].as_str() {
                "--set" => {
                    let pair = next()?;
                    let (key, value) = pair
                        .split_once('=')
                        .ok_or_else(|| SceneError::NotAPair { pair: pair.clone() })?;
                    match values.iter_mut().find(|(k, _)| k == key) {
                        Some(slot) => slot.1 = value.to_string(),
                        None => {
                            return Err(SceneError::UnknownKnob {
                                knob: key.to_string(),
                                scene: name,
                                known: knobs.iter().map(|k| k.name).collect(),
                            });
                        }
                    }
                    i += 2;
                }
                "--out" => {
                    out = PathBuf::from(next()?);
                    i += 2;
                }
                // `cargo bench` passes it to a benchmark run as a scene.
                "--bench" => i += 1,
                other => {
                    return Err(SceneError::UnexpectedArgument {
                        argument: other.to_string(),
                    })
                }
            }
        }
        let staging = beside(&out, "new");
        Ok(Scene {
            name,
            knobs: knobs.to_vec(),
            values,
            out,
            staging,
        })
    }

    /// The value given on the command line for `--set name=…`, before the
    /// knobs are known (a scene whose knobs depend on it, like `explore`).
    pub fn peek(name: &str) -> Option<String> {
        let args: Vec<String> = std::env::args().collect();
        args.windows(2)
            .filter(|w| w[0] == "--set")
            .filter_map(|w| w[1].split_once('='))
            .filter(|(k, _)| *k == name)
            .map(|(_, v)| v.to_string())
            .next_back()
    }

    /// The values of the knobs of [`parameter_knobs`], in declaration order.
    pub fn parameter_values(
        &self,
        info: &mechlab_runtime::registry::ModelInfo,
    ) -> Result<Vec<f64>, SceneError> {
        info.parameter_names
            .iter()
            .map(|n| {
                let value = self.get::<f64>(n, Range::Any)?;
                info.check_parameter(n, value)?;
                Ok(value)
            })
            .collect()
    }

    /// The text value of a knob.
    pub fn text(&self, name: &str) -> &str {
        &self
            .values
            .iter()
            .find(|(k, _)| k == name)
            .unwrap_or_else(|| panic!("scene {} has no knob {name}", self.name))
            .1
    }

    /// The value of knob `name` as a `T` (a number, a count, a list: the
    /// kinds of the declared settings), within `range`; else an error
    /// naming the knob, its value, and what it takes.
    pub fn get<T: SettingValue>(&self, name: &str, range: Range) -> Result<T, SceneError> {
        let text = self.text(name);
        T::from_text(text)
            .filter(|value| value.within(&range))
            .ok_or_else(|| SceneError::BadValue {
                name: name.into(),
                value: text.into(),
                reason: ValueProblem::Kind {
                    kind: T::KIND,
                    range: range.to_string(),
                },
            })
    }

    /// The knobs and their values, for summaries: numbers as numbers,
    /// lists of numbers as arrays, anything else as text.
    pub fn settings(&self) -> serde_json::Value {
        let value = |text: &str| -> serde_json::Value {
            let numbers: Option<Vec<f64>> = text
                .split(',')
                .map(|x| x.trim().parse::<f64>().ok().filter(|v| v.is_finite()))
                .collect();
            match numbers {
                Some(v) if v.len() == 1 => serde_json::json!(v[0]),
                Some(v) => serde_json::json!(v),
                None => serde_json::Value::String(text.to_string()),
            }
        };
        let map: serde_json::Map<String, serde_json::Value> = self
            .values
            .iter()
            .map(|(k, v)| (k.clone(), value(v)))
            .collect();
        serde_json::Value::Object(map)
    }

    pub fn knobs(&self) -> &[Knob] {
        &self.knobs
    }

    /// Path of an output file, creating the output directory.
    /// Where `file` is written (in the staging folder until published).
    pub fn path(&self, file: &str) -> Result<PathBuf, SceneError> {
        std::fs::create_dir_all(&self.staging).map_err(|source| SceneError::Io {
            path: self.staging.clone(),
            source,
        })?;
        Ok(self.staging.join(file))
    }

    /// Writes `file` (a `.png` name) and, where it stays small (no shaded
    /// map, few points), the same figure as SVG beside it.
    pub fn save_figure(
        &self,
        figure: &mechlab_runtime::plot::Figure,
        file: &str,
    ) -> Result<PathBuf, SceneError> {
        let path = self.path(file)?;
        let io = |path: &Path, source: std::io::Error| SceneError::Io {
            path: path.to_path_buf(),
            source,
        };
        figure.save(&path).map_err(|e| io(&path, e))?;
        eprintln!("wrote {}", self.out.join(file).display());
        if figure.svg_is_cheap() {
            let svg = path.with_extension("svg");
            figure.save_svg(&svg).map_err(|e| io(&svg, e))?;
            eprintln!(
                "wrote {}",
                self.out.join(file).with_extension("svg").display()
            );
        }
        Ok(self.out.join(file))
    }

    /// Writes CSV through the csv crate: the header, then one record per
    /// row (tuples or structs of numbers and text); floats in the shortest
    /// form that reads back exactly.
    pub fn write_csv<R: serde::Serialize>(
        &self,
        file: &str,
        header: &[&str],
        rows: impl IntoIterator<Item = R>,
    ) -> Result<PathBuf, SceneError> {
        let path = self.path(file)?;
        let io = |source: std::io::Error| SceneError::Io {
            path: path.clone(),
            source,
        };
        let mut writer = csv::WriterBuilder::new()
            .has_headers(false)
            .from_path(&path)
            .map_err(|e| io(e.into()))?;
        writer.write_record(header).map_err(|e| io(e.into()))?;
        for row in rows {
            writer.serialize(row).map_err(|e| io(e.into()))?;
        }
        writer.flush().map_err(io)?;
        eprintln!("wrote {}", self.out.join(file).display());
        Ok(self.out.join(file))
    }

    pub fn write_text(&self, file: &str, text: &str) -> Result<PathBuf, SceneError> {
        self.write_bytes(file, text.as_bytes())
    }

    pub fn write_bytes(&self, file: &str, bytes: &[u8]) -> Result<PathBuf, SceneError> {
        let path = self.path(file)?;
        std::fs::write(&path, bytes).map_err(|source| SceneError::Io {
            path: path.clone(),
            source,
        })?;
        eprintln!("wrote {}", self.out.join(file).display());
        Ok(self.out.join(file))
    }

    /// Writes `summary.json` (with the scene's settings added).
    pub fn write_summary<S: serde::Serialize>(&self, summary: &S) -> Result<PathBuf, SceneError> {
        let mut summary = serde_json::to_value(summary).map_err(|source| SceneError::Summary {
            scene: self.name,
            source,
        })?;
        if let serde_json::Value::Object(map) = &mut summary {
            map.insert("scene".into(), self.name.into());
            map.insert("settings".into(), self.settings());
        }
        let text = serde_json::to_string_pretty(&summary).expect("JSON values serialise");
        let path = self.write_text("summary.json", &text)?;
        self.publish()?;
        Ok(path)
    }

    /// Replaces the output folder by the staging folder: the old results
    /// are moved aside, the new ones renamed into place, the old removed.
    fn publish(&self) -> Result<(), SceneError> {
        let io = |path: &Path, source: std::io::Error| SceneError::Io {
            path: path.to_path_buf(),
            source,
        };
        let old = beside(&self.out, "old");
        if self.out.exists() {
            let _ = std::fs::remove_dir_all(&old);
            std::fs::rename(&self.out, &old).map_err(|e| io(&self.out, e))?;
        }
        std::fs::rename(&self.staging, &self.out).map_err(|e| io(&self.out, e))?;
        let _ = std::fs::remove_dir_all(&old);
        Ok(())
    }
}

/// A hidden sibling of a folder, unique to this process (`out/.scene.new-123`).
fn beside(folder: &Path, role: &str) -> PathBuf {
    let name = folder
        .file_name()
        .map(|n| n.to_string_lossy().to_string())
        .unwrap_or_else(|| "scene".into());
    folder.with_file_name(format!(".{name}.{role}-{}", std::process::id()))
}

/// Writes a file atomically: a temporary file in the same directory, then rename.
pub fn write_atomic(path: &Path, bytes: &[u8]) -> std::io::Result<()> {
    let file_name = path
        .file_name()
        .map(|n| n.to_string_lossy().to_string())
        .unwrap_or_default();
    let temporary = path.with_file_name(format!(".{file_name}.tmp{}", std::process::id()));
    {
        let mut f = std::fs::File::create(&temporary)?;
        f.write_all(bytes)?;
        f.sync_all()?;
    }
    std::fs::rename(&temporary, path)
}

/// A progress bar on stderr with rate and ETA (indicatif); it can be
/// advanced from rayon workers (`inc`) or set from the main thread
/// (`update`), and stays silent when stderr is not a terminal.
pub struct Progress {
    bar: indicatif::ProgressBar,
}

impl Progress {
    pub fn new(label: &str, total: usize) -> Progress {
        let bar = indicatif::ProgressBar::new(total.max(1) as u64);
        bar.set_style(
            indicatif::ProgressStyle::with_template(
                "{msg} [{bar:30}] {pos}/{len} ({per_sec}, eta {eta})",
            )
            .expect("a valid template")
            .progress_chars("=> "),
        );
        bar.set_message(label.to_string());
        Progress { bar }
    }
    /// Sets the number of finished items.
    pub fn update(&self, done: usize) {
        self.bar.set_position(done as u64);
        if done as u64 >= self.bar.length().unwrap_or(0) {
            self.bar.finish();
        }
    }
    /// One more item finished (from any thread).
    pub fn inc(&self) {
        self.advance(1);
    }
    /// `count` more items finished (from any thread).
    pub fn advance(&self, count: usize) {
        self.bar.inc(count as u64);
        if self.bar.position() >= self.bar.length().unwrap_or(0) {
            self.bar.finish();
        }
    }
}

/// The stack of every thread that runs an analysis: the integrators keep
/// their stages in arrays of the state's size, which for the variational
/// equations of a 16-link chain (32 + 32² numbers a state) pass the 2 MiB
/// of a thread's default stack. Only the pages a thread touches are
/// committed.
pub const STACK_BYTES: usize = 256 << 20;

/// Runs a scene's body and turns an error into a message and exit code 2.
/// The body runs on a thread of [`STACK_BYTES`], and so do rayon's workers.
pub fn run(body: impl FnOnce() -> Result<(), SceneError> + Send) {
    // Fails only if the pool was built already, with the stacks it has.
    let _ = rayon::ThreadPoolBuilder::new()
        .stack_size(STACK_BYTES)
        .build_global();
    let outcome = std::thread::scope(|scope| {
        std::thread::Builder::new()
            .name("scene".into())
            .stack_size(STACK_BYTES)
            .spawn_scoped(scope, body)
            .map(|thread| thread.join())
    });
    match outcome {
        Ok(Ok(Ok(()))) => {}
        Ok(Ok(Err(e))) => {
            eprintln!("error: {e}");
            std::process::exit(2);
        }
        // The panic has printed its message.
        Ok(Err(_)) => std::process::exit(101),
        Err(e) => {
            eprintln!("error: cannot start the scene's thread: {e}");
            std::process::exit(2);
        }
    }
}
