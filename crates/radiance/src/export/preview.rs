//! `<name>-preview.rad`: a tiny scene to look at the material. A unit
//! sphere rests on a 10 × 10 floor, both made of the material, under a
//! sun-sized `source` and a dim uniform sky. The material itself is not in
//! the file: oconv gets the static or the θ_in-dependent material file
//! first, so the same scene shows either.

use super::num::num;
use super::static_material::comment_block;
use brtf_fit::FitResult;
use std::f64::consts::{FRAC_1_SQRT_2, PI};

/// Full apex angle of the sun-like source, degrees.
const SUN_APEX_DEG: f64 = 0.533;
/// Sun direction (towards the sun): 45° high, from the camera's right, so
/// the sphere shows the highlight over all incidence angles at once.
const SUN_DIRECTION: [f64; 3] = [FRAC_1_SQRT_2, 0.0, FRAC_1_SQRT_2];
/// Sky radiance (uniform glow); the sun's normal irradiance is π.
const SKY_RADIANCE: f64 = 0.3;

/// The scene text.
pub(crate) fn text(result: &FitResult, name: &str, static_file: &str, with_theta: bool) -> String {
    let stem = format!("{name}-preview");
    let omega = 2.0 * PI * (1.0 - (0.5 * SUN_APEX_DEG.to_radians()).cos());
    // Normal irradiance π, so a white Lambertian floor facing the sun has radiance 1.
    let sun = PI / omega;
    let view = "-vtv -vp 6 -6 3 -vd -6 6 -2.6 -vu 0 0 1 -vh 30 -vv 30";
    let mut h = vec![
        format!(
            "{stem}.rad: preview scene for the material \"{name}\" (fit \"{}\", {}), written by brtf {}.",
            super::report::ascii(&result.name),
            result.config.kind,
            env!("CARGO_PKG_VERSION")
        ),
        "A unit sphere on a 10 x 10 floor, both of the material, z up; a sun 45 deg high from"
            .into(),
        "the camera's right and a dim uniform sky. The material is not in this file: give".into(),
        "oconv one of the material files first. In this folder:".into(),
        String::new(),
        format!("  oconv {static_file} {stem}.rad > {stem}.oct"),
    ];
    if with_theta {
        h.push(format!(
            "  oconv {name}-theta.rad {stem}.rad > {stem}-theta.oct     (theta_in-dependent)"
        ));
    }
    h.extend([
        String::new(),
        "Render (about a minute at 512 x 512; rpict finds the .cal through RAYPATH, which".into(),
        "includes the current folder by default):".into(),
        String::new(),
        format!("  rpict {view} -x 512 -y 512 -ab 1 -ad 1024 -as 256 -aa .1 -ps 1 {stem}.oct > {stem}.hdr"),
        format!("  ra_tiff {stem}.hdr {stem}.tif     (or: ximage {stem}.hdr)"),
    ]);
    let mut s = comment_block(&h);
    let [dx, dy, dz] = SUN_DIRECTION;
    s += &format!(
        "\nvoid light {stem}_sun_light\n0\n0\n3 {l} {l} {l}\n\n\
         {stem}_sun_light source {stem}_sun\n0\n0\n4 {dx} {dy} {dz} {SUN_APEX_DEG}\n\n\
         void glow {stem}_sky_glow\n0\n0\n4 {sky} {sky} {sky} 0\n\n\
         {stem}_sky_glow source {stem}_sky\n0\n0\n4 0 0 1 180\n\n\
         {name} sphere {stem}_ball\n0\n0\n4 0 0 1 1\n\n\
         {name} polygon {stem}_floor\n0\n0\n12\n  -5 -5 0\n   5 -5 0\n   5  5 0\n  -5  5 0\n",
        l = num(sun),
        sky = num(SKY_RADIANCE),
    );
    s
}
