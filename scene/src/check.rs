//! The checks of a scene file, section by section: each turns the parsed TOML
//! ([`super::file`]) into the scene's values, or refuses it naming the file, the key and
//! the line ([`Reporter`]).

use frf_core::env::EnvSource;
use frf_core::sun::Sun;
use frf_reflectance::project::FloorModel;
use glam::Vec3;

use super::file::{
    At, CameraToml, CompositeToml, LightingToml, OutputToml, Reporter, SceneToml, WalkKeyToml,
};
use super::{
    BackdropSpec, Instance, LightKey, MAX_DISTANCE_M, MAX_FRAMES, MAX_INTENSITY, MAX_SIDE_PX,
    MAX_TIME_S, Preview, Probe, Probes, ShadowSpec, TimeInterpolation,
};
use crate::error::Result;
use crate::path::{CameraPath, Orbit, Trajectory};
use crate::probes::ProbeLayout;
use crate::walk::{WalkKey, WalkPath};
use frf_render::composite::GroundLook;
use frf_render::morph::Variant;

/// Albedo of `floor = "ground"`: a mid-grey ground.
const GROUND_FLOOR_ALBEDO: f32 = 0.3;

fn word<'w>(r: &Reporter, field: &str, v: &'w At<String>, allowed: &[&str]) -> Result<&'w str> {
    let s = v.get_ref().as_str();
    if allowed.contains(&s) {
        Ok(s)
    } else {
        Err(r.error(
            field,
            v.span(),
            format!("`{s}`: expected one of {allowed:?}"),
        ))
    }
}

fn finite<T: Copy + std::fmt::Display + Into<f64>>(
    r: &Reporter,
    field: &str,
    v: &At<T>,
) -> Result<T> {
    let x = *v.get_ref();
    if x.into().is_finite() {
        Ok(x)
    } else {
        Err(r.error(field, v.span(), format!("{x} is not a finite number")))
    }
}

fn env(r: &Reporter, field: &str, v: &At<String>) -> Result<EnvSource> {
    let source: EnvSource = v
        .get_ref()
        .parse()
        .map_err(|e: String| r.error(field, v.span(), e))?;
    Ok(match source {
        EnvSource::File(p) => EnvSource::File(r.resolve(&p.to_string_lossy())),
        other => other,
    })
}

fn ground(r: &Reporter, v: &At<toml::Value>) -> Result<GroundLook> {
    let number = |x: &toml::Value| x.as_float().or_else(|| x.as_integer().map(|i| i as f64));
    let albedo = match v.get_ref() {
        toml::Value::String(s) if s == "env" => return Ok(GroundLook::Environment),
        toml::Value::Array(a) if a.len() == 3 => {
            let c: Vec<f64> = a.iter().filter_map(number).collect();
            (c.len() == 3).then(|| [c[0] as f32, c[1] as f32, c[2] as f32])
        }
        other => number(other).map(|a| [a as f32; 3]),
    };
    match albedo {
        Some(a) if a.iter().all(|x| (0.0..=1.0).contains(x)) => Ok(GroundLook::Albedo(a)),
        _ => Err(r.error(
            "composite.ground",
            v.span(),
            "expected \"env\", an albedo in 0 to 1, or [r, g, b]",
        )),
    }
}

/// `time`: start, end and frame rate.
pub fn time(r: &Reporter, raw: &SceneToml) -> Result<(f64, f64, f64)> {
    let t = raw.time.get_ref();
    let (start, end, fps) = (
        finite(r, "time.start", &t.start)?,
        finite(r, "time.end", &t.end)?,
        finite(r, "time.fps", &t.fps)?,
    );
    for (key, at, v) in [("time.start", &t.start, start), ("time.end", &t.end, end)] {
        if v.abs() > MAX_TIME_S {
            return Err(r.error(
                key,
                at.span(),
                format!("{v} s: expected within ±{MAX_TIME_S:e} s"),
            ));
        }
    }
    if end < start {
        return Err(r.error(
            "time.end",
            t.end.span(),
            format!("{end} s is before start {start} s"),
        ));
    }
    if !(fps > 0.0 && fps <= 1000.0) {
        return Err(r.error(
            "time.fps",
            t.fps.span(),
            format!("{fps}: expected (0, 1000]"),
        ));
    }
    if (end - start) * fps > MAX_FRAMES as f64 {
        return Err(r.error(
            "time",
            raw.time.span(),
            format!("{} frames: at most {MAX_FRAMES}", (end - start) * fps),
        ));
    }
    Ok((start, end, fps))
}

/// `time.interpolate`: `None` when not given.
pub fn interpolate(r: &Reporter, raw: &SceneToml) -> Result<Option<TimeInterpolation>> {
    let Some(v) = &raw.time.get_ref().interpolate else {
        return Ok(None);
    };
    Ok(Some(
        match word(r, "time.interpolate", v, &["flow", "nearest"])? {
            "flow" => TimeInterpolation::Flow,
            _ => TimeInterpolation::Nearest,
        },
    ))
}

/// What `output` sets: frame size (if given), exposure in stops, preview, variant.
pub type OutputSettings = (Option<(u32, u32)>, f32, Preview, Variant);

/// `output`: size, exposure, preview and variant.
pub fn output(r: &Reporter, o: &OutputToml) -> Result<OutputSettings> {
    let size = match &o.size {
        Some(s) => {
            let &[w, h] = s.get_ref().as_slice() else {
                return Err(r.error(
                    "output.size",
                    s.span(),
                    format!("{} values: a size is [width, height]", s.get_ref().len()),
                ));
            };
            if !(1..=MAX_SIDE_PX).contains(&w) || !(1..=MAX_SIDE_PX).contains(&h) {
                return Err(r.error(
                    "output.size",
                    s.span(),
                    format!("{w}x{h}: each side 1 to {MAX_SIDE_PX}"),
                ));
            }
            Some((w, h))
        }
        None => None,
    };
    let exposure = finite(r, "output.exposure", &o.exposure)?;
    if exposure.abs() > 30.0 {
        return Err(r.error(
            "output.exposure",
            o.exposure.span(),
            format!("{exposure} stops: expected -30 to 30"),
        ));
    }
    let preview = match word(r, "output.preview", &o.preview, &["apng", "gif", "none"])? {
        "apng" => Preview::Apng,
        "gif" => Preview::Gif,
        _ => Preview::None,
    };
    let variant = Variant::ALL
        .into_iter()
        .find(|v| v.name() == o.variant.get_ref())
        .ok_or_else(|| {
            r.error(
                "output.variant",
                o.variant.span(),
                format!(
                    "`{}`: expected one of {}",
                    o.variant.get_ref(),
                    Variant::ALL.map(Variant::name).join(", ")
                ),
            )
        })?;
    Ok((size, exposure, preview, variant))
}

/// `lighting`: its keys (the base first) and what lights the floor conditions.
pub fn lighting(r: &Reporter, l: &At<LightingToml>) -> Result<(Vec<LightKey>, FloorModel)> {
    let span = l.span();
    let l = l.get_ref();
    // Keyed lighting may leave the base environment to its first key.
    let base_env = match (&l.env, l.key.first().and_then(|k| k.get_ref().env.as_ref())) {
        (Some(e), _) => env(r, "lighting.env", e)?,
        (None, Some(e)) => env(r, "lighting.key[0].env", e)?,
        (None, None) => {
            return Err(r.error(
                "lighting.env",
                span,
                "no environment: give env = \"FILE\" (or \"sky\", \"uniform\", \"none\"), or an env in the first [[lighting.key]]",
            ));
        }
    };
    let mut lighting = vec![LightKey {
        time: f64::NEG_INFINITY,
        env: base_env,
        yaw_deg: turn(r, "lighting.yaw_deg", &l.yaw_deg)?,
        intensity: finite(r, "lighting.intensity", &l.intensity)?,
    }];
    for (i, k) in l.key.iter().enumerate() {
        let key = k.get_ref();
        let field = |name: &str| format!("lighting.key[{i}].{name}");
        let prev = lighting.last().expect("at least the base").clone();
        let time = finite(r, &field("time"), &key.time)?;
        if time <= prev.time {
            return Err(r.error(
                &field("time"),
                key.time.span(),
                format!("{time} s does not follow the previous key"),
            ));
        }
        lighting.push(LightKey {
            time,
            env: match &key.env {
                Some(e) => env(r, &field("env"), e)?,
                None => prev.env.clone(),
            },
            yaw_deg: match &key.yaw_deg {
                Some(y) => turn(r, &field("yaw_deg"), y)?,
                None => prev.yaw_deg,
            },
            intensity: match &key.intensity {
                Some(v) => finite(r, &field("intensity"), v)?,
                None => prev.intensity,
            },
        });
    }
    for (i, k) in lighting.iter().enumerate() {
        if !(k.intensity >= 0.0 && k.intensity <= MAX_INTENSITY) {
            let span = if i == 0 {
                l.intensity.span()
            } else {
                l.key[i - 1].span()
            };
            return Err(r.error(
                "lighting.intensity",
                span,
                format!("{}: expected 0 to 10^6", k.intensity),
            ));
        }
    }
    // `none` alone shows the field unlit, which nothing turns or scales; with a sun it is
    // a black sky the sun lights, which a key may turn and scale like any light.
    if lighting.iter().any(|k| k.env == EnvSource::None) && lighting.len() > 1 && l.sun.is_none() {
        return Err(r.error(
            "lighting.env",
            span,
            "`none` cannot be keyframed: it shows the field unlit (give a sun to light it, \
             which keys then turn and scale)",
        ));
    }
    let floor = match word(r, "lighting.floor", &l.floor, &["env", "ground"])? {
        "env" => FloorModel::Environment,
        _ => FloorModel::LambertianGround {
            albedo: [GROUND_FLOOR_ALBEDO; 3],
        },
    };
    Ok((lighting, floor))
}

/// `lighting.probe`: the light probes, when given; a refusal names the probe: no map
/// (`none`), a position or yaw that is not finite, an intensity outside 0 to 10^6, two
/// probes at one place, too many.
pub fn probes(r: &Reporter, l: &At<LightingToml>) -> Result<Option<Probes>> {
    let raw = &l.get_ref().probe;
    if raw.is_empty() {
        return Ok(None);
    }
    let none = |e: &Option<At<String>>| e.as_ref().is_some_and(|e| e.get_ref() == "none");
    if none(&l.get_ref().env) || l.get_ref().key.iter().any(|k| none(&k.get_ref().env)) {
        return Err(r.error(
            "lighting.probe",
            raw[0].span(),
            "probes relight the walkers: the scene's env (its backdrop) cannot be \"none\"",
        ));
    }
    let mut probes = Vec::with_capacity(raw.len());
    for (i, p) in raw.iter().enumerate() {
        let field = |name: &str| format!("lighting.probe[{i}].{name}");
        let v = p.get_ref();
        let source = env(r, &field("env"), &At::new(p.span(), v.env.clone()))?;
        if source == EnvSource::None {
            return Err(r.error(
                &field("env"),
                p.span(),
                "a probe needs a map: a .hdr/.exr file, an frf env-sh file, \"sky\" or \"uniform\"",
            ));
        }
        let position = Vec3::from(v.position);
        if !position.is_finite() || position.abs().max_element() > MAX_DISTANCE_M {
            return Err(r.error(&field("position"), p.span(), "finite metres within 10 km"));
        }
        if let Err(problem) = frf_core::light::checked_turn(v.yaw_deg) {
            return Err(r.error(&field("yaw_deg"), p.span(), problem));
        }
        if !(v.intensity >= 0.0 && v.intensity <= MAX_INTENSITY) {
            return Err(r.error(
                &field("intensity"),
                p.span(),
                format!("{}: expected 0 to 10^6", v.intensity),
            ));
        }
        probes.push(Probe {
            position,
            env: source,
            yaw: frf_core::light::turn_radians(v.yaw_deg),
            intensity: v.intensity,
            suns: v.suns,
        });
    }
    let points = probes
        .iter()
        .map(|p| glam::Vec2::new(p.position.x, p.position.z))
        .collect();
    let layout = ProbeLayout::new(points).map_err(|(i, problem)| {
        let span = raw.get(i).map_or(0..0, |p| p.span());
        r.error(&format!("lighting.probe[{i}]"), span, problem)
    })?;
    Ok(Some(Probes { probes, layout }))
}

/// `camera`: an orbit or keys.
pub fn camera(r: &Reporter, camera: &At<CameraToml>) -> Result<Trajectory> {
    let c = camera.get_ref();
    let camera = match (&c.orbit, c.key.is_empty()) {
        (Some(o), true) => {
            let orbit = o.get_ref();
            let orbit = Orbit {
                radius: orbit.radius,
                height: orbit.height,
                start_deg: orbit.start_deg,
                sweep_deg: orbit.sweep_deg,
                look_at: Vec3::from(orbit.look_at),
                fov_deg: orbit.fov_deg,
            };
            orbit
                .validate()
                .map_err(|e| r.error("camera.orbit", o.span(), e))?;
            Trajectory::Orbit(orbit)
        }
        (None, false) => {
            let keys = c.key.iter().map(|k| *k.get_ref()).collect();
            Trajectory::Path(
                CameraPath::new(keys).map_err(|e| r.error("camera.key", camera.span(), e))?,
            )
        }
        _ => {
            return Err(r.error(
                "camera",
                camera.span(),
                "give either an orbit or keys ([[camera.key]])",
            ));
        }
    };
    Ok(camera)
}

/// `composite`: the backdrop and the shadow, checked against the camera and lighting.
pub fn composite(
    r: &Reporter,
    comp: &CompositeToml,
    (camera, camera_span): (&Trajectory, &At<CameraToml>),
    lighting: &[LightKey],
) -> Result<(BackdropSpec, ShadowSpec)> {
    let backdrop = match word(
        r,
        "composite.backdrop",
        &comp.backdrop,
        &["env", "plate", "none"],
    )? {
        "env" => BackdropSpec::Environment(match &comp.ground {
            Some(g) => ground(r, g)?,
            None => GroundLook::Environment,
        }),
        "plate" => {
            let plate = comp.plate.as_ref().ok_or_else(|| {
                r.error(
                    "composite.plate",
                    comp.backdrop.span(),
                    "backdrop = \"plate\" needs plate = \"FILE\"",
                )
            })?;
            if !matches!(camera, Trajectory::Path(p) if p.keys.len() == 1) {
                return Err(r.error(
                    "camera",
                    camera_span.span(),
                    "a plate is seen by its own camera: give one camera key",
                ));
            }
            BackdropSpec::Plate(r.resolve(plate.get_ref()))
        }
        _ => BackdropSpec::None,
    };
    if matches!(backdrop, BackdropSpec::Environment(_))
        && lighting.iter().any(|k| k.env == EnvSource::None)
    {
        return Err(r.error(
            "composite.backdrop",
            comp.backdrop.span(),
            "an environment backdrop needs an environment (lighting.env)",
        ));
    }
    let shadow = match word(
        r,
        "composite.shadow",
        &comp.shadow,
        &["maps", "traced", "none"],
    )? {
        "maps" => ShadowSpec::Maps,
        "traced" => ShadowSpec::Traced,
        _ => ShadowSpec::None,
    };
    Ok((backdrop, shadow))
}

/// `instance`: the walkers (one at the origin when none is given), standing or walking a
/// path; a refusal names the walker, the field (the key of a path) and the line.
pub fn instances(r: &Reporter, raw: &SceneToml) -> Result<Vec<Instance>> {
    let mut instances = Vec::new();
    for (i, inst) in raw.instance.iter().enumerate() {
        let v = inst.get_ref();
        let key = |name: &str| format!("instance[{i}].{name}");
        let bad = |name: &str, value: String, range: &str| {
            Err(r.error(&key(name), inst.span(), format!("{value}: {range}")))
        };
        if !(v.time_offset.is_finite() && v.time_offset.abs() <= 1e6) {
            return bad(
                "time_offset",
                v.time_offset.to_string(),
                "finite seconds within 10^6",
            );
        }
        if !v.key.is_empty() {
            if v.position.is_some() || v.heading_deg.is_some() {
                return Err(r.error(
                    &key("key"),
                    inst.span(),
                    "a walker on a path gives keys, not position or heading_deg (give \
                     heading_deg at its keys)",
                ));
            }
            instances.push(walker_on_path(r, i, &v.key, v.time_offset)?);
            continue;
        }
        let position = v.position.unwrap_or([0.0; 3]);
        let heading_deg = v.heading_deg.unwrap_or(0.0);
        if !position
            .iter()
            .all(|c| c.is_finite() && c.abs() <= MAX_DISTANCE_M)
        {
            return bad(
                "position",
                format!("{position:?}"),
                "finite metres within 10 km",
            );
        }
        if !heading_deg.is_finite() {
            return bad("heading_deg", heading_deg.to_string(), "a finite angle");
        }
        if position[1] != 0.0 {
            return Err(r.error(
                &format!("instance[{i}].position"),
                inst.span(),
                "walkers stand on the ground: y must be 0",
            ));
        }
        instances.push(Instance::standing(
            Vec3::from(position),
            radians(heading_deg),
            v.time_offset,
        ));
    }
    if instances.is_empty() {
        instances.push(Instance::standing(Vec3::ZERO, 0.0, 0.0));
    }
    Ok(instances)
}

/// A turn in degrees from a scene file (a light's yaw), refused naming the field where it
/// is not finite or beyond [`frf_core::light::MOST_TURN_DEG`].
fn turn(r: &Reporter, field: &str, v: &At<f64>) -> Result<f64> {
    frf_core::light::checked_turn(*v.get_ref()).map_err(|problem| r.error(field, v.span(), problem))
}

/// An angle in degrees as radians, reduced to a turn in double precision first (so that
/// 10^9 degrees is the same heading as its remainder).
fn radians(deg: f64) -> f32 {
    deg.rem_euclid(360.0).to_radians() as f32
}

/// Walker `i` on the path of `keys`, its walk `time_offset` seconds ahead.
fn walker_on_path(
    r: &Reporter,
    i: usize,
    keys: &[At<WalkKeyToml>],
    time_offset: f64,
) -> Result<Instance> {
    let walk_keys = keys
        .iter()
        .map(|k| {
            let k = k.get_ref();
            WalkKey {
                time: k.time,
                position: Vec3::from(k.position),
                heading: k.heading_deg.map(|h| radians(h) as f64),
            }
        })
        .collect();
    let path = WalkPath::new(walk_keys).map_err(|(j, problem)| {
        let span = keys.get(j).map_or(0..0, |k| k.span());
        r.error(&format!("instance[{i}].key[{j}]"), span, problem)
    })?;
    Ok(Instance::walking(path, time_offset))
}

/// `lighting.sun`, when given: refused naming the field for a direction that is not one
/// (or given twice, or not at all), an elevation outside ±90°, an angular diameter
/// outside (0, 20]°, or a strength that is not one finite, non-negative value.
pub fn sun(r: &Reporter, l: &At<LightingToml>) -> Result<Option<Sun>> {
    let Some(at) = &l.get_ref().sun else {
        return Ok(None);
    };
    let (s, span) = (at.get_ref(), at.span());
    let bad = |field: &str, problem: String| {
        r.error(&format!("lighting.sun.{field}"), span.clone(), problem)
    };
    let finite = |field: &str, v: f32| {
        if v.is_finite() {
            Ok(v)
        } else {
            Err(bad(field, format!("{v} is not a finite number")))
        }
    };
    let direction = match (s.direction, s.azimuth_deg, s.elevation_deg) {
        (Some(d), None, None) => {
            let d = Vec3::from_array(d);
            if !d.is_finite() || d == Vec3::ZERO {
                return Err(bad("direction", format!("{d} is not a direction")));
            }
            d
        }
        (None, Some(az), Some(el)) => {
            let az = frf_core::light::checked_turn(az).map_err(|e| bad("azimuth_deg", e))?;
            let el = finite("elevation_deg", el)?;
            if !(-90.0..=90.0).contains(&el) {
                return Err(bad("elevation_deg", format!("{el}° is not within ±90°")));
            }
            let az = frf_core::light::turn_radians(az);
            frf_core::light::direction_from_azimuth_elevation(az, el.to_radians())
        }
        _ => {
            return Err(bad(
                "direction",
                "give direction = [x, y, z], or azimuth_deg and elevation_deg (not both)".into(),
            ));
        }
    };
    let diameter = finite(
        "angular_diameter_deg",
        s.angular_diameter_deg
            .unwrap_or(frf_core::sun::SUN_DIAMETER_DEG),
    )?;
    if !(diameter > 0.0 && diameter <= frf_core::sun::MAX_DIAMETER_DEG) {
        return Err(bad(
            "angular_diameter_deg",
            format!(
                "{diameter}° is not within (0, {}]°",
                frf_core::sun::MAX_DIAMETER_DEG
            ),
        ));
    }
    let strength = match (s.illuminance, s.radiance) {
        (Some(e), None) => finite("illuminance", e)?,
        (None, Some(l)) => finite("radiance", l)? * Sun::solid_angle(diameter),
        _ => {
            return Err(bad(
                "illuminance",
                "give illuminance = E or radiance = L (one of them)".into(),
            ));
        }
    };
    let colour = s.colour.unwrap_or([1.0; 3]);
    if strength < 0.0 || colour.iter().any(|c| !c.is_finite() || *c < 0.0) {
        return Err(bad(
            if strength < 0.0 {
                "illuminance"
            } else {
                "colour"
            },
            "a sun's strength and colour are finite and not negative".into(),
        ));
    }
    Sun::new(direction, diameter, colour.map(|c| c * strength))
        .map(Some)
        .map_err(|e| bad("illuminance", e.to_string()))
}
