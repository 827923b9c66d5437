//! Values as a command line writes them, each parsed in one place: sizes, points, pose
//! lists and ranges, angles and turns, fields of view, light tolerances, orbits, suns and
//! grounds. Each parser returns a `String` error that names the value and what it expects,
//! as clap prints it; the bounds are the scene file's (a command line and a scene refuse
//! the same values).

use frf_core::argument::given_twice;
use frf_core::sun::Sun;
use serde::Serialize;

use crate::MAX_SIDE_PX;

/// Comma-separated finite numbers, for the flag `what`.
fn numbers(s: &str, what: &str) -> Result<Vec<f32>, String> {
    s.split(',')
        .map(|t| match t.trim().parse::<f32>() {
            Ok(v) if v.is_finite() => Ok(v),
            _ => Err(format!("{what} `{s}`: `{t}` is not a finite number")),
        })
        .collect()
}

/// Parses `x,y,z` (metres).
pub fn parse_point(s: &str) -> Result<[f32; 3], String> {
    let v = numbers(s, "point")?;
    <[f32; 3]>::try_from(v).map_err(|_| format!("point `{s}`: expected x,y,z"))
}

/// Parses an angle in degrees: a finite number (a scene file refuses the same values).
pub fn parse_degrees(s: &str) -> Result<f32, String> {
    let v: f32 = s
        .trim()
        .parse()
        .map_err(|e| format!("`{s}`: {e} (degrees)"))?;
    if !v.is_finite() {
        return Err(format!("`{s}` degrees: an angle is a finite number"));
    }
    Ok(v)
}

/// Parses a turn (a light's yaw, a sun's azimuth) in degrees: read in double precision
/// and kept as the same turn within ±180° ([`frf_core::light::within_half_turn`]: 1e9 is
/// -80, the turn 1e9 mod 360 names), refused where not finite or beyond
/// [`frf_core::light::MOST_TURN_DEG`].
pub fn parse_turn(s: &str) -> Result<f64, String> {
    let v: f64 = s
        .trim()
        .parse()
        .map_err(|e| format!("`{s}`: {e} (degrees)"))?;
    let v = frf_core::light::checked_turn(v).map_err(|e| format!("`{s}`: {e}"))?;
    Ok(frf_core::light::within_half_turn(v))
}

/// Parses a vertical field of view in degrees, within the range a camera path allows.
pub fn parse_fov(s: &str) -> Result<f32, String> {
    use crate::path::{MAX_FOV_DEG, MIN_FOV_DEG};
    let v = parse_degrees(s)?;
    if !(v > MIN_FOV_DEG && v < MAX_FOV_DEG) {
        return Err(format!(
            "`{s}` degrees: a vertical field of view is within ({MIN_FOV_DEG}, {MAX_FOV_DEG})"
        ));
    }
    Ok(v)
}

/// Parses a light tolerance: `DEG` (a walker's heading) or `DEG,WEIGHT` (and a probe's
/// weight).
pub fn parse_light_tolerance(s: &str) -> Result<crate::shot::LightTolerance, String> {
    let bad = || {
        format!(
            "light tolerance `{s}`: expected DEG or DEG,WEIGHT (a heading within 0 to 180 \
             degrees, a probe's weight within 0 to 1)"
        )
    };
    let mut parts = s
        .split(',')
        .map(|p| p.trim().parse::<f32>().map_err(|_| bad()));
    let deg = parts.next().ok_or_else(bad)??;
    let weight = parts.next().transpose()?.unwrap_or(0.0);
    if parts.next().is_some() || !(0.0..=180.0).contains(&deg) || !(0.0..=1.0).contains(&weight) {
        return Err(bad());
    }
    Ok(crate::shot::LightTolerance {
        heading: deg.to_radians(),
        weight,
    })
}

/// Parses `WxH`, each side 1 to [`MAX_SIDE_PX`] (as a scene file's size).
pub fn parse_size(s: &str) -> Result<(u32, u32), String> {
    let (w, h) = s
        .split_once(['x', 'X'])
        .ok_or_else(|| format!("size `{s}`: expected WxH"))?;
    let parse = |t: &str| {
        t.trim()
            .parse::<u32>()
            .map_err(|e| format!("size `{s}`: {e}"))
    };
    let (w, h) = (parse(w)?, parse(h)?);
    if !(1..=MAX_SIDE_PX).contains(&w) || !(1..=MAX_SIDE_PX).contains(&h) {
        return Err(format!(
            "size `{s}`: each side must be 1 to {MAX_SIDE_PX} pixels"
        ));
    }
    Ok((w, h))
}

/// Parses `--poses`: a list `0,1` or a half-open range `0..4`.
pub fn parse_poses(s: &str) -> Result<Vec<u32>, String> {
    const LIKE: &str = "poses, e.g. 0,1 or 0..4";
    let bad = || LIKE.to_string();
    if s.trim().is_empty() {
        return Err(format!("{LIKE} (none given)"));
    }
    let most = frf_core::capture::MAX_POSES_PER_CYCLE;
    if let Some((a, b)) = s.split_once("..") {
        let (a, b): (u32, u32) = (
            a.trim().parse().map_err(|_| bad())?,
            b.trim().parse().map_err(|_| bad())?,
        );
        if a >= b {
            return Err(format!(
                "a range whose end is after its start, e.g. 0..4 for poses 0 to 3 ({a}..{b} \
                 holds no pose)"
            ));
        }
        if b > most {
            return Err(format!("poses below {most} (a cycle holds at most {most})"));
        }
        return Ok((a..b).collect());
    }
    let poses: Vec<u32> = s
        .split(',')
        .map(|p| p.trim().parse().map_err(|_| bad()))
        .collect::<Result<_, _>>()?;
    if let Some(p) = poses.iter().find(|&&p| p >= most) {
        return Err(format!(
            "poses below {most} (pose {p} is beyond any cycle of at most {most})"
        ));
    }
    if let Some((k, p)) = given_twice(&poses) {
        return Err(format!(
            "each pose once (pose {p} is given twice, the second time at place {k})"
        ));
    }
    Ok(poses)
}

/// The poses `flag` names ([`parse_poses`]), refused naming the flag and the value.
pub fn poses_arg(flag: &str, s: &str) -> Result<Vec<u32>, frf_core::BadArgument> {
    parse_poses(s).map_err(|e| frf_core::BadArgument::new(flag, s, e))
}

/// `--sun AZIMUTH,ELEVATION[,DIAMETER[,ILLUMINANCE]]`.
#[derive(Clone, Copy, Debug, Serialize, PartialEq)]
pub struct SunSpec {
    /// Degrees.
    pub azimuth_deg: f32,
    /// Degrees.
    pub elevation_deg: f32,
    /// Degrees.
    pub diameter_deg: f32,
    /// `∫ L dω` over the disc.
    pub illuminance: f32,
}

impl SunSpec {
    /// The sun it names.
    pub fn sun(&self) -> Result<Sun, String> {
        let d = frf_core::light::direction_from_azimuth_elevation(
            self.azimuth_deg.to_radians(),
            self.elevation_deg.to_radians(),
        );
        Sun::new(d, self.diameter_deg, [self.illuminance; 3]).map_err(|e| format!("--sun: {e}"))
    }
}

/// Parses `--sun`.
pub fn parse_sun(s: &str) -> Result<SunSpec, String> {
    let v: Vec<f64> = s
        .split(',')
        .map(|x| x.trim().parse::<f64>())
        .collect::<Result<_, _>>()
        .map_err(|_| {
            format!("{s:?} is not AZIMUTH,ELEVATION[,DIAMETER[,ILLUMINANCE]] in numbers")
        })?;
    if !(2..=4).contains(&v.len()) || v.iter().any(|x| !x.is_finite()) {
        return Err(format!(
            "{s:?} is not AZIMUTH,ELEVATION[,DIAMETER[,ILLUMINANCE]] (2 to 4 finite numbers)"
        ));
    }
    let azimuth = frf_core::light::checked_turn(v[0]).map_err(|e| format!("azimuth {e}"))?;
    let spec = SunSpec {
        azimuth_deg: frf_core::light::within_half_turn(azimuth) as f32,
        elevation_deg: v[1] as f32,
        diameter_deg: v
            .get(2)
            .map_or(frf_core::sun::SUN_DIAMETER_DEG, |&d| d as f32),
        illuminance: v.get(3).map_or(10.0, |&e| e as f32),
    };
    if !(-90.0..=90.0).contains(&spec.elevation_deg) {
        return Err(format!(
            "elevation {}° is not within ±90°",
            spec.elevation_deg
        ));
    }
    spec.sun()?;
    Ok(spec)
}

/// `--orbit RADIUS,HEIGHT[,SWEEP_DEG]`.
#[derive(Clone, Copy, Debug, Serialize, PartialEq)]
pub struct OrbitSpec {
    /// Metres from the axis.
    pub radius: f32,
    /// Camera height, metres.
    pub height: f32,
    /// Degrees swept.
    pub sweep_deg: f32,
}

/// Parses `RADIUS,HEIGHT`, metres (a camera circling the walker at one height).
pub fn parse_radius_height(s: &str) -> Result<(f32, f32), String> {
    match numbers(s, "radius and height")?[..] {
        [r, h] => Ok((r, h)),
        _ => Err(format!("`{s}`: expected RADIUS,HEIGHT in metres")),
    }
}

/// Parses `RADIUS,HEIGHT[,SWEEP_DEG]`.
pub fn parse_orbit(s: &str) -> Result<OrbitSpec, String> {
    let v = numbers(s, "orbit")?;
    if !(2..=3).contains(&v.len()) {
        return Err(format!("orbit `{s}`: expected RADIUS,HEIGHT[,SWEEP_DEG]"));
    }
    Ok(OrbitSpec {
        radius: v[0],
        height: v[1],
        sweep_deg: v.get(2).copied().unwrap_or(360.0),
    })
}

/// The ground of an environment backdrop: `env` (the environment below the horizon) or
/// a Lambertian albedo `A` or `R,G,B`.
#[derive(Clone, Copy, Debug, Serialize, PartialEq)]
pub enum GroundArg {
    /// The environment's lower hemisphere.
    Env,
    /// A Lambertian ground of this albedo.
    Albedo([f32; 3]),
}

/// Parses `env`, `A` or `R,G,B` (albedos in 0..=1).
pub fn parse_ground(s: &str) -> Result<GroundArg, String> {
    if s == "env" {
        return Ok(GroundArg::Env);
    }
    let v = numbers(s, "ground")?;
    let albedo = match v[..] {
        [a] => [a; 3],
        [r, g, b] => [r, g, b],
        _ => return Err(format!("ground `{s}`: expected env, an albedo A or R,G,B")),
    };
    if albedo.iter().any(|a| !(0.0..=1.0).contains(a)) {
        return Err(format!("ground `{s}`: albedos lie in 0 to 1"));
    }
    Ok(GroundArg::Albedo(albedo))
}

/// `--headings`: camera azimuths, degrees.
#[derive(Clone, Debug)]
pub struct Headings(pub Vec<f32>);

/// Parses `--headings`: a count of headings spread evenly from 0°, or a list of
/// degrees (one heading: `90,`), each direction once.
pub fn parse_headings(s: &str) -> Result<Headings, String> {
    if let Ok(n) = s.trim().parse::<usize>() {
        if !(1..=64).contains(&n) {
            return Err(format!("{n} headings: 1 to 64"));
        }
        return Ok(Headings(
            (0..n).map(|i| i as f32 * 360.0 / n as f32).collect(),
        ));
    }
    // A list of one heading ends with its comma (`90,`), where `90` alone is a count.
    let list = s
        .trim()
        .strip_suffix(',')
        .filter(|l| !l.contains(','))
        .unwrap_or(s);
    let headings: Vec<f32> = list
        .split(',')
        .map(|a| {
            a.trim()
                .parse::<f32>()
                .ok()
                .filter(|a| a.is_finite() && a.abs() <= 360.0)
                .ok_or_else(|| {
                    format!("{s:?}: a count of headings or a list of degrees from -360 to 360")
                })
        })
        .collect::<Result<_, _>>()?;
    // Two headings of one direction draw the same row twice.
    let turn = |a: f32| a.rem_euclid(360.0);
    for (k, &a) in headings.iter().enumerate() {
        if let Some(&b) = headings[..k].iter().find(|&&b| turn(b) == turn(a)) {
            return Err(format!("{s:?}: headings {b} and {a} are one direction"));
        }
    }
    Ok(Headings(headings))
}

/// `--sprite-size`: a frame's `WxH`, within what a sheet allows (named once, not first
/// by the general size parser's wider bound).
pub fn parse_sprite_size(s: &str) -> Result<(u32, u32), String> {
    let size = parse_size(s).map_err(|_| {
        format!(
            "{s:?}: expected WxH, 1 to {} pixels a side",
            crate::sprites::MOST_FRAME_SIDE
        )
    })?;
    match crate::sprites::frame_size_problem(size) {
        Some(problem) => Err(problem),
        None => Ok(size),
    }
}

/// `--walkers`: counts, each once.
#[derive(Clone, Debug)]
pub struct Counts(pub Vec<usize>);

/// Parses a number of megapixels: finite, 0 or more (NaN and -1 skipped the CPU reference
/// without a word).
pub fn parse_megapixels(s: &str) -> Result<f64, String> {
    let v: f64 = s
        .trim()
        .parse()
        .map_err(|e| format!("`{s}`: {e} (megapixels)"))?;
    if !(v.is_finite() && v >= 0.0) {
        return Err(format!(
            "`{s}` megapixels: a finite number, 0 or more (0 renders no CPU reference)"
        ));
    }
    Ok(v)
}

/// Parses `1,10,40`: every count a whole number, none empty (a stray comma) or given
/// twice (it was timed twice).
pub fn parse_counts(s: &str) -> Result<Counts, String> {
    let counts: Vec<usize> = s
        .split(',')
        .map(|c| match c.trim() {
            "" => Err(format!(
                "{s:?}: an empty count (a comma with nothing beside it)"
            )),
            c => c
                .parse()
                .map_err(|_| format!("{s:?}: {c:?} is not a whole number")),
        })
        .collect::<Result<_, _>>()?;
    if let Some((k, c)) = given_twice(&counts) {
        return Err(format!(
            "{s:?}: {c} is given twice (the second time at place {k})"
        ));
    }
    Ok(Counts(counts))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn parsers_accept_what_they_document_and_name_what_they_refuse() {
        assert_eq!(parse_size("320x448"), Ok((320, 448)));
        assert!(parse_size("0x10").unwrap_err().contains("1 to 8192"));
        assert!(parse_size("320").unwrap_err().contains("WxH"));
        assert_eq!(parse_point("-2, 1.2,-2"), Ok([-2.0, 1.2, -2.0]));
        assert!(parse_point("1,2").unwrap_err().contains("x,y,z"));
        assert!(
            parse_point("1,nan,2")
                .unwrap_err()
                .contains("not a finite number")
        );
        assert_eq!(parse_poses("0..3"), Ok(vec![0, 1, 2]));
        assert_eq!(parse_poses("4,1"), Ok(vec![4, 1]));
        // An empty or reversed range is named as such, and the flag and value once (it
        // read "--poses \"\": expected --poses \"\": expected ...").
        let e = poses_arg("--poses", "3..3").unwrap_err().to_string();
        assert!(e.contains("3..3 holds no pose"), "{e}");
        assert_eq!(e.matches("--poses").count(), 1, "{e}");
        assert!(
            parse_poses("1..0")
                .unwrap_err()
                .contains("1..0 holds no pose")
        );
        assert!(parse_poses("").unwrap_err().contains("none given"));
        assert!(parse_poses(" ").unwrap_err().contains("none given"));
        // Bounded before anything is allocated (issue 35: 0..4294967295 took 23 GB).
        assert!(
            parse_poses("0..4294967295")
                .unwrap_err()
                .contains("at most")
        );
        assert!(parse_poses("1,4294967295").unwrap_err().contains("beyond"));
        // A pose given twice is refused (it exported, merged and rendered twice).
        assert!(
            parse_poses("0,0")
                .unwrap_err()
                .contains("pose 0 is given twice")
        );
        assert!(parse_poses("2,1,2").unwrap_err().contains("twice"));
        let o = parse_orbit("3,1.2").unwrap();
        assert_eq!((o.radius, o.height, o.sweep_deg), (3.0, 1.2, 360.0));
        assert_eq!(parse_ground("env"), Ok(GroundArg::Env));
        assert_eq!(parse_ground("0.3"), Ok(GroundArg::Albedo([0.3; 3])));
        assert!(parse_ground("1.5").unwrap_err().contains("0 to 1"));
        assert!(parse_ground("0.1,0.2").unwrap_err().contains("R,G,B"));
    }

    /// `--headings`: a number is a count, a list is degrees, and one heading is a list of
    /// one with its comma (`90,`: one whole-degree heading could not be asked for).
    #[test]
    fn headings_are_a_count_or_a_list_of_one_or_more() {
        assert_eq!(parse_headings("90,").unwrap().0, vec![90.0]);
        assert_eq!(parse_headings(" -45, ").unwrap().0, vec![-45.0]);
        assert_eq!(
            parse_headings("4").unwrap().0,
            vec![0.0, 90.0, 180.0, 270.0]
        );
        assert_eq!(parse_headings("0,90").unwrap().0, vec![0.0, 90.0]);
        assert!(parse_headings("0,90,").is_err());
        assert!(parse_headings(",").is_err());
    }
}
