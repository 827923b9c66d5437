//! Scripts: the viewer driven without a person (`frf view ... --script FILE`), one
//! command per line, `#` starting a comment. A script is read and checked whole before
//! the window opens; an error names the file, the line and the command.
//!
//! ```text
//! camera 2.5 1.4 3.0  0 0.9 0  30   # position, point looked at, vertical fov (degrees)
//! view 4 1                          # the captured view of column 4, row 1
//! snap                              # the captured view nearest the camera
//! orbit 15 -5                       # degrees about the point looked at (azimuth, elevation)
//! dolly 0.8                         # distance times 0.8
//! time 0.25                         # seconds of the scene's clock
//! step 1                            # poses forward (negative: back)
//! play / pause
//! env sky                           # an environment offered: a file given (its path or
//!                                   # name), sky, uniform
//! yaw 90                            # degrees
//! intensity 1.5
//! variant fourway                   # nearest, linear, twoway, fourway, fourway-e06, ...
//! backdrop env                      # none, env or plate
//! shadow off                        # on or off
//! layer alpha                       # composite, subject, backdrop, alpha or shadow
//! exposure 1                        # stops
//! key                               # record the camera at the current time (--record)
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
    Time(f32),
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
    let text = frf_core::io::read_text(path, frf_render::scene::MAX_FILE_BYTES)?;
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
        let command = command(content).map_err(bad)?;
        out.push(Line {
            line: i + 1,
            command,
        });
    }
    Ok(out)
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
        "time" => Command::Time(numbers(&args, 1)?[0]),
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
            if v < 0.0 {
                return Err("the intensity must not be negative".into());
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
        other => return Err(format!("no command {other:?}")),
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
    fn a_bad_line_is_named() {
        for (text, line, words) in [
            ("time 1\ncamera 0 0 0 0 0\n", 2, "takes 7 number(s)"),
            ("yaw nan\n", 1, "not a finite number"),
            ("\n\nfly 3\n", 3, "no command \"fly\""),
            ("variant fiveway\n", 1, "no variant \"fiveway\""),
            ("screenshot shot.jpg\n", 1, ".png or an .exr"),
            ("camera 1 1 1 0 0 0 180\n", 1, "outside (0, 180)"),
            ("shadow maybe\n", 1, "on or off"),
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
