//! Scripts: the viewer driven without a person (`frf view ... --script FILE`), one
//! command per line, `#` starting a comment. A script is read and checked whole before
//! the window opens; an error names the file, the line and the command.
//!
//! The commands, their arguments and units are listed once, in [`COMMANDS`]; `frf view
//! --help` prints them ([`help`]). For example:
//!
//! ```text
//! camera 2.5 1.4 3.0  0 0.9 0  30   # position, point looked at, vertical fov (degrees)
//! env sky
//! wait 3                            # let 3 frames be drawn
//! screenshot shot.png               # the frame shown: .png as frf render writes, or .exr
//! quit
//! ```
//!
//! Commands up to a `wait`, `screenshot` or `quit` take effect together before the next
//! frame is drawn; a screenshot is of that frame.

use std::path::{Path, PathBuf};

use frf_render::gpu::present::ShownLayer;
use frf_render::morph::Variant;
use glam::Vec3;

use crate::ViewError;

/// Every command: its name, its arguments and what it does (the help of `frf view
/// --script`, and the usage an error repeats).
pub const COMMANDS: &[(&str, &str, &str)] = &[
    (
        "camera",
        "X Y Z  TX TY TZ  FOV",
        "camera at X Y Z looking at TX TY TZ (metres), vertical field of view FOV (degrees)",
    ),
    ("view", "U V", "the captured view of column U, row V"),
    ("snap", "", "the captured view nearest the camera"),
    (
        "orbit",
        "AZ EL",
        "turn about the point looked at by AZ, EL degrees",
    ),
    (
        "dolly",
        "F",
        "distance to the point looked at times F (> 0)",
    ),
    ("time", "T", "seconds of the scene's clock"),
    ("step", "N", "N poses forward (negative: back)"),
    ("play", "", "play the walk at its rate"),
    ("pause", "", "stop it"),
    (
        "env",
        "NAME",
        "an environment offered: a file given (path or name), sky, uniform",
    ),
    (
        "yaw",
        "DEG",
        "turn the environment about the vertical, degrees",
    ),
    ("intensity", "K", "environment times K (0 to 1e6)"),
    (
        "variant",
        "NAME",
        "interpolation: nearest, linear, twoway, fourway, fourway-e06, ...",
    ),
    ("backdrop", "NAME", "none, env or plate"),
    ("shadow", "on|off", "the ground shadow"),
    (
        "layer",
        "NAME",
        "what is shown: composite, subject, backdrop, alpha or shadow",
    ),
    (
        "exposure",
        "STOPS",
        "exposure of the frame shown, -30 to 30 stops",
    ),
    (
        "key",
        "",
        "record the camera at the current time (with --record)",
    ),
    ("wait", "N", "let N frames be drawn"),
    (
        "screenshot",
        "FILE",
        "write the frame shown: .png (as frf render writes it) or .exr",
    ),
    ("quit", "", "close the viewer"),
];

/// The script language in words, for `frf view --help`.
pub fn help() -> String {
    let mut text = String::from(
        "Run the commands of FILE without a person, then close. One command per line, `#` \
         starts a comment; the commands up to a `wait`, `screenshot` or `quit` take effect \
         together before the next frame is drawn. Commands:\n",
    );
    for (name, args, what) in COMMANDS {
        let call = format!("{name} {args}");
        text.push_str(&format!("  {call:<28} {what}\n"));
    }
    text.push_str(
        "Example: camera 2.5 1.4 3.0  0 0.9 0  30, then wait 2, screenshot shot.png, quit",
    );
    text
}

/// One command of a script.
#[derive(Debug, Clone, PartialEq)]
pub enum Command {
    /// Camera position, point looked at, vertical field of view in degrees.
    Camera(Vec3, Vec3, f32),
    /// The captured view of column `.0`, row `.1`.
    View(usize, usize),
    /// The captured view nearest the camera.
    Snap,
    /// Degrees of azimuth and elevation about the point looked at.
    Orbit(f32, f32),
    /// Distance times this.
    Dolly(f32),
    /// Seconds of the scene's clock.
    Time(f64),
    /// Poses forward (negative: back).
    Step(i32),
    /// Play the walk at its rate.
    Play,
    /// Stop it.
    Pause,
    /// An environment offered, by path, name or word.
    Env(String),
    /// Degrees.
    Yaw(f32),
    /// Multiplier of the environment.
    Intensity(f32),
    /// Interpolation.
    Variant(Variant),
    /// `none`, `env` or `plate`.
    Backdrop(String),
    /// Shadow on or off.
    Shadow(bool),
    /// What is shown.
    Layer(ShownLayer),
    /// Stops.
    Exposure(f32),
    /// Record the camera at the current time.
    Key,
    /// Let this many frames be drawn.
    Wait(u32),
    /// Write the frame shown.
    Screenshot(PathBuf),
    /// Close the viewer.
    Quit,
}

impl Command {
    /// Whether the command waits for a frame to be drawn first.
    pub fn after_a_frame(&self) -> bool {
        matches!(
            self,
            Command::Wait(_) | Command::Screenshot(_) | Command::Quit
        )
    }
}

/// A command and the line it was read from (1-based).
#[derive(Debug, Clone, PartialEq)]
pub struct Line {
    /// Line number.
    pub line: usize,
    /// The command.
    pub command: Command,
}

/// Reads and checks the script at `path`; relative screenshot paths are relative to the
/// working directory, as a command line's.
pub fn load(path: &Path) -> Result<Vec<Line>, ViewError> {
    let text = frf_core::io::read_text(path, frf_scene::MAX_FILE_BYTES)?;
    parse(path, &text)
}

/// Checks `text`, a script read from `path`.
pub fn parse(path: &Path, text: &str) -> Result<Vec<Line>, ViewError> {
    let mut out = Vec::new();
    for (i, raw) in text.lines().enumerate() {
        let content = raw.split('#').next().unwrap_or("").trim();
        if content.is_empty() {
            continue;
        }
        let bad = |why: String| ViewError::Script {
            path: path.to_path_buf(),
            line: i + 1,
            problem: format!("`{content}`: {why}"),
        };
        let command = command(content)
            .map_err(|why| match usage(content) {
                Some(u) => format!("{why} (usage: {u})"),
                None => why,
            })
            .map_err(bad)?;
        out.push(Line {
            line: i + 1,
            command,
        });
    }
    Ok(out)
}

/// How the command `content` starts with is called, if it is one.
fn usage(content: &str) -> Option<String> {
    let name = content.split_whitespace().next()?;
    let (name, args, _) = COMMANDS.iter().find(|(n, _, _)| *n == name)?;
    Some(format!("{name} {args}").trim_end().to_string())
}

/// `n` finite numbers.
fn numbers(args: &[&str], n: usize) -> Result<Vec<f32>, String> {
    if args.len() != n {
        return Err(format!("takes {n} number(s), got {}", args.len()));
    }
    args.iter()
        .map(|a| {
            a.parse::<f32>()
                .ok()
                .filter(|v| v.is_finite())
                .ok_or_else(|| format!("{a:?} is not a finite number"))
        })
        .collect()
}

fn one_word<'a>(args: &[&'a str]) -> Result<&'a str, String> {
    match args {
        [w] => Ok(w),
        _ => Err(format!("takes one word, got {}", args.len())),
    }
}

fn command(content: &str) -> Result<Command, String> {
    let mut words = content.split_whitespace();
    let name = words.next().unwrap_or("");
    let args: Vec<&str> = words.collect();
    let none = |c: Command| {
        if args.is_empty() {
            Ok(c)
        } else {
            Err("takes nothing".to_string())
        }
    };
    Ok(match name {
        "camera" => {
            let v = numbers(&args, 7)?;
            if !(v[6] > 0.0 && v[6] < 180.0) {
                return Err(format!("field of view {} is outside (0, 180)", v[6]));
            }
            let most = frf_scene::MAX_DISTANCE_M;
            if let Some(c) = v[..6].iter().find(|c| c.abs() > most) {
                return Err(format!(
                    "coordinate {c} is beyond {most} m of the origin (position and point \
                     looked at, metres)"
                ));
            }
            if Vec3::new(v[0], v[1], v[2]).distance(Vec3::new(v[3], v[4], v[5])) < 1e-4 {
                return Err("the camera and the point it looks at coincide".into());
            }
            Command::Camera(
                Vec3::new(v[0], v[1], v[2]),
                Vec3::new(v[3], v[4], v[5]),
                v[6],
            )
        }
        "view" => {
            if args.len() != 2 {
                return Err("takes a column and a row".into());
            }
            let index = |a: &str| {
                a.parse::<usize>()
                    .map_err(|_| format!("{a:?} is not a view index"))
            };
            Command::View(index(args[0])?, index(args[1])?)
        }
        "snap" => none(Command::Snap)?,
        "orbit" => {
            let v = numbers(&args, 2)?;
            Command::Orbit(v[0], v[1])
        }
        "dolly" => {
            let v = numbers(&args, 1)?;
            if v[0] <= 0.0 {
                return Err("the factor must be positive".into());
            }
            Command::Dolly(v[0])
        }
        "time" => {
            // Read in 64 bits, as every time of a scene.
            let w = one_word(&args)?;
            match w.parse::<f64>() {
                Ok(t) if t.is_finite() => Command::Time(t),
                _ => return Err(format!("{w:?} is not a finite number of seconds")),
            }
        }
        "step" => Command::Step(
            one_word(&args)?
                .parse()
                .map_err(|_| "takes a whole number of poses".to_string())?,
        ),
        "play" => none(Command::Play)?,
        "pause" => none(Command::Pause)?,
        "env" => Command::Env(one_word(&args)?.to_string()),
        "yaw" => Command::Yaw(numbers(&args, 1)?[0]),
        "intensity" => {
            let v = numbers(&args, 1)?[0];
            let most = frf_scene::MAX_INTENSITY;
            if !(0.0..=most).contains(&v) {
                return Err(format!("intensity {v}: expected 0 to {most:e}"));
            }
            Command::Intensity(v)
        }
        "variant" => {
            let w = one_word(&args)?;
            Command::Variant(
                Variant::ALL
                    .into_iter()
                    .find(|v| v.name() == w)
                    .ok_or_else(|| {
                        format!(
                            "no variant {w:?} (one of {})",
                            Variant::ALL.map(Variant::name).join(", ")
                        )
                    })?,
            )
        }
        "backdrop" => {
            let w = one_word(&args)?;
            if !["none", "env", "plate"].contains(&w) {
                return Err(format!("no backdrop {w:?} (none, env or plate)"));
            }
            Command::Backdrop(w.to_string())
        }
        "shadow" => match one_word(&args)? {
            "on" => Command::Shadow(true),
            "off" => Command::Shadow(false),
            w => return Err(format!("{w:?}: on or off")),
        },
        "layer" => {
            let w = one_word(&args)?;
            Command::Layer(ShownLayer::parse(w).ok_or_else(|| {
                format!(
                    "no layer {w:?} (one of {})",
                    ShownLayer::ALL.map(ShownLayer::name).join(", ")
                )
            })?)
        }
        "exposure" => {
            let v = numbers(&args, 1)?[0];
            if v.abs() > 30.0 {
                return Err("exposure is within [-30, 30] stops".into());
            }
            Command::Exposure(v)
        }
        "key" => none(Command::Key)?,
        "wait" => Command::Wait(
            one_word(&args)?
                .parse()
                .map_err(|_| "takes a number of frames".to_string())?,
        ),
        "screenshot" => {
            let w = one_word(&args)?;
            let p = PathBuf::from(w);
            let ext = p
                .extension()
                .and_then(|e| e.to_str())
                .map(str::to_ascii_lowercase);
            if !matches!(ext.as_deref(), Some("png" | "exr")) {
                return Err("a screenshot is a .png or an .exr".into());
            }
            Command::Screenshot(p)
        }
        "quit" => none(Command::Quit)?,
        other => {
            let names: Vec<&str> = COMMANDS.iter().map(|c| c.0).collect();
            return Err(format!(
                "no command {other:?} (the commands: {}; `frf view --help` says what each takes)",
                names.join(", ")
            ));
        }
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_command_parses() {
        let text = "\
# a tour
camera 2.5 1.4 3.0  0 0.9 0  30
view 4 1
snap
orbit 15 -5   # degrees
dolly 0.8
time 0.25
step -2
play
pause
env sky
yaw 90
intensity 1.5
variant fourway
backdrop env
shadow off
layer alpha
exposure 1
key
wait 3
screenshot out/shot.png
quit
";
        let lines = parse(Path::new("s.txt"), text).expect("a script");
        assert_eq!(lines.len(), 21);
        assert_eq!(lines[0].line, 2);
        assert_eq!(
            lines[0].command,
            Command::Camera(Vec3::new(2.5, 1.4, 3.0), Vec3::new(0.0, 0.9, 0.0), 30.0)
        );
        assert_eq!(lines[6].command, Command::Step(-2));
        assert_eq!(lines[13].command, Command::Backdrop("env".into()));
        assert_eq!(lines[15].command, Command::Layer(ShownLayer::Alpha));
        assert_eq!(
            lines[19].command,
            Command::Screenshot(PathBuf::from("out/shot.png"))
        );
        assert!(lines[20].command.after_a_frame());
        assert!(!lines[0].command.after_a_frame());
    }

    #[test]
    fn the_help_lists_every_command_the_parser_knows() {
        let help = help();
        for (name, args, _) in COMMANDS {
            assert!(help.contains(&format!("{name} {args}")), "{name}");
            // The parser knows it: whatever it says of the arguments, not "no command".
            let e = command(&format!("{name} ?? ?? ??"))
                .err()
                .unwrap_or_default();
            assert!(!e.starts_with("no command"), "{name}: {e}");
        }
        let e = command("fly 3").expect_err("no such command");
        assert!(e.contains("camera, view, snap"), "{e}");
    }

    #[test]
    fn a_bad_line_is_named() {
        for (text, line, words) in [
            ("time 1\ncamera 0 0 0 0 0\n", 2, "takes 7 number(s)"),
            ("yaw nan\n", 1, "not a finite number"),
            ("\n\nfly 3\n", 3, "no command \"fly\""),
            ("variant fiveway\n", 1, "no variant \"fiveway\""),
            ("screenshot shot.jpg\n", 1, ".png or an .exr"),
            ("camera 1 1 1 0 0 0 180\n", 1, "outside (0, 180)"),
            // Issue 35: a far camera was said to coincide with its target, and an
            // intensity of 1e38 drew a white frame.
            ("camera 1e30 0 0 0 0.9 0 40\n", 1, "beyond 10000 m"),
            ("camera 1 1 1 1 1 1 40\n", 1, "coincide"),
            ("intensity 1e38\n", 1, "expected 0 to 1e6"),
            ("shadow maybe\n", 1, "on or off"),
            // Issue 35: a first script missed the field of view, which nothing had said.
            (
                "camera 2.2 1.4 2.8 0 0.9 0\n",
                1,
                "usage: camera X Y Z  TX TY TZ  FOV",
            ),
            ("quit now\n", 1, "takes nothing"),
        ] {
            let e = parse(Path::new("tour.txt"), text)
                .expect_err(text)
                .to_string();
            assert!(e.contains(&format!("tour.txt:{line}")), "{e}");
            assert!(e.contains(words), "{e}");
        }
    }
}
