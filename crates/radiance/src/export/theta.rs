//! The θ_in-dependent material: `<name>-theta.rad` and its function file
//! `<name>-theta.cal`.
//!
//! The parameters follow the fitted θ_in table, evaluated at the θ_in of
//! each light source sample (`acos |l·n|`). The material is a `BRTDfunc`
//! whose three channel functions compute brtf-model's BSDF; its real
//! arguments keep, as constant diffuse parts, the smallest diffuse
//! reflectance and transmittance over θ_in, so that indirect light still
//! reaches the diffuse part (the functions add the rest). When only the
//! roughness changes with θ_in, Radiance's own `plasfunc`/`metfunc`/
//! `transfunc` suffice: their constant arguments carry colour,
//! specularity and transmission, and the function only the lobe.

use super::cal::{
    CHANNEL_FUNCTIONS, CalModel, Entry, LOBE_FUNCTION, MIRROR_VARIABLES, THROUGH_VARIABLES,
};
use super::num::sig;
use super::pieces::Pieces;
use super::report::{self, ascii};
use super::static_material::comment_block;
use super::{ExportError, cal_file_name, theta_file_name};
use crate::primitive::{Primitive, format_primitive};
use brtf_fit::{FitResult, ParamTable};
use brtf_model::{Composite, FTINY, MaterialKind, Shape, Variant};
use glam::DVec3;

/// Samples per table segment when searching minima over θ_in.
const GRID_PER_SEGMENT: usize = 400;
/// The same for a (θ_in, φ_in) table, at this many azimuths (every 2.5°).
const GRID_PER_SEGMENT_WITH_AZIMUTH: usize = 40;
const GRID_AZIMUTHS: usize = 144;
/// Rtrace's Fresnel switch (specularity at or above it, roughness 0).
const FRESNEL_THRESHOLD: f64 = 0.017999;
/// The constant diffuse parts are this fraction of the smallest diffuse
/// reflectance over θ_in, so the functions' remainder stays positive.
const FLOOR_MARGIN: f64 = 1.0 - 1e-4;

/// The two files and notes for the user.
pub(crate) struct Theta {
    pub rad: String,
    pub cal: String,
    pub notes: Vec<String>,
}

/// Builds both files from the table.
pub(crate) fn build(
    result: &FitResult,
    table: &ParamTable,
    name: &str,
    static_file: &str,
    colour: Option<[f64; 3]>,
) -> Result<Theta, ExportError> {
    let kind = table.kind;
    let shape = table.shape();
    // Plain ASCII: `metal`, `metal x2 lobes`, `plastic2 (orientation fitted)`.
    let label = ascii(&shape.label());
    let options = result.options();
    let variant = options.variant;
    check_rows(table)?;
    let pieces = Pieces::of(table);
    let grid = grid(table)?;
    let iso = !kind.is_anisotropic();
    let any_pure = iso
        && grid.iter().any(|m| {
            m.components()
                .iter()
                .any(|(_, p)| p.args()[4] * p.args()[4] <= FTINY)
        });
    let azimuth = table.depends_on_azimuth();
    let lobe_only =
        variant != Variant::Ward1992 && !any_pure && !azimuth && only_roughness_varies(table);
    let entry = if lobe_only {
        Entry::Lobe
    } else {
        let (rd0, td0) = diffuse_floor(variant, &grid);
        Entry::Brtd {
            rd0,
            td0,
            deltas: any_pure,
        }
    };
    let model = CalModel {
        kind,
        shape,
        variant,
        fresnel_k: options.fresnel_k,
        orientation: table.orientation,
        pieces: &pieces,
        entry,
        azimuth: azimuth.then_some(table),
    };
    let cal_name = cal_file_name(name);
    let (lo, hi) = table.range();
    let rows = table.theta_in.len();
    let mut notes = Vec::new();
    if any_pure {
        notes.push(format!(
            "{}: some θ_in have roughness 0; their mirror part is a traced ray",
            theta_file_name(name)
        ));
    }

    // ---- the .cal file ----
    let mut ch = vec![
        format!(
            "{cal_name}: function file of the theta_in-dependent Radiance material \"{name}\"",
            cal_name = cal_name
        ),
        format!(
            "({label}, variant {variant}), written by brtf {} (brtf export). Used by {}.",
            env!("CARGO_PKG_VERSION"),
            theta_file_name(name)
        ),
        String::new(),
    ];
    ch.extend(report::provenance(result));
    ch.push(String::new());
    ch.push(format!(
        "The table: {rows} incidences, theta_in {lo}-{hi} deg, {:?} interpolation.",
        table.method
    ));
    ch.push(format!(
        "  theta_in  {}",
        shape
            .param_names()
            .iter()
            .map(|n| format!("{n:>9}"))
            .collect::<Vec<_>>()
            .join(" ")
    ));
    for (theta, args) in table.theta_in.iter().zip(&table.args) {
        ch.push(format!(
            "  {:>8}  {}",
            sig(*theta, 4),
            args.iter()
                .map(|a| format!("{:>9}", sig(*a, 5)))
                .collect::<Vec<_>>()
                .join(" ")
        ));
    }
    if azimuth {
        ch.push(
            "Rows with several azimuths show their mean; the parameters follow phi_in too".into(),
        );
        ch.push("(section 1b), each row's incidences at their azimuths.".into());
    }
    ch.push("Fit quality per incidence:".into());
    ch.extend(report::incidences(result));
    ch.push(String::new());
    ch.push(
        "theta_in is the angle between the surface normal and the direction to the light".into(),
    );
    ch.push("source sample, on whichever side the light is (two-sided, like plastic).".into());
    let cal = model.text(&ch);

    // ---- the .rad file ----
    let mut h = vec![
        format!(
            "{}: theta_in-dependent Radiance material \"{name}\" ({label}, variant {variant}),",
            theta_file_name(name)
        ),
        format!(
            "written by brtf {} (brtf export) from fit \"{}\" created {}.",
            env!("CARGO_PKG_VERSION"),
            ascii(&result.name),
            ascii(&result.provenance.created)
        ),
        String::new(),
        format!(
            "Parameters: the fitted table ({rows} incidences, theta_in {lo}-{hi} deg, {:?}),",
            table.method
        ),
    ];
    h.extend(lines(&format!(
        "evaluated at theta_in = the angle between the surface normal and the direction to
each light source sample (outside the measured range the end values hold).
Function file: {cal_name}. Radiance finds it through RAYPATH: render in this folder,
or add the folder to RAYPATH (docs/radiance.md).

"
    )));
    let primitive = match entry {
        Entry::Lobe => {
            let radiance_type = match kind {
                MaterialKind::Plastic | MaterialKind::Plastic2 => "plasfunc",
                MaterialKind::Metal | MaterialKind::Metal2 => "metfunc",
                MaterialKind::Trans | MaterialKind::Trans2 => "transfunc",
            };
            let args = &table.args[0];
            let mut reals = vec![args[0], args[1], args[2], args[3]];
            let constants = if let (Some(t), Some(ts)) = trans_indices(kind) {
                reals.extend([args[t], args[ts]]);
                "colour, specularity,\ntransmissivity and transmitted-specular fraction"
            } else {
                "colour and\nspecularity"
            };
            let lobes = if shape.lobes > 1 {
                "the weighted sum of\nthe specular lobes"
            } else {
                "the specular lobe"
            };
            h.extend(lines(&format!(
                "Material: {radiance_type}. Only the roughness changes with theta_in, so the real
arguments hold the constant {constants}, and the function {LOBE_FUNCTION} computes
{lobes} at the light's theta_in ({variant} formulas).

What differs from a static {label} in a rendering:
  - the specular lobe responds to light sources only; indirect light (-ab) reaches
    the constant diffuse and specular fractions as if they were diffuse;
  - the lobe is not sampled: other objects do not appear in the glossy reflection
    (or transmission);"
            )));
            Primitive {
                modifier: "void".into(),
                kind: radiance_type.into(),
                name: name.into(),
                strings: vec![LOBE_FUNCTION.into(), cal_name.clone()],
                ints: Vec::new(),
                reals,
                line: 0,
            }
        }
        Entry::Brtd { rd0, td0, deltas } => {
            let pick = |names: [&str; 3]| names.map(String::from).to_vec();
            let zero = || ["0", "0", "0"].map(String::from).to_vec();
            let mut strings = if deltas {
                pick(MIRROR_VARIABLES)
            } else {
                zero()
            };
            strings.extend(if deltas && kind.is_transmitting() {
                pick(THROUGH_VARIABLES)
            } else {
                zero()
            });
            strings.extend(pick(CHANNEL_FUNCTIONS));
            strings.push(cal_name.clone());
            let mut reals = Vec::with_capacity(9);
            reals.extend(rd0);
            reals.extend(rd0);
            reals.extend(td0);
            h.extend(lines(&format!(
                "Material: BRTDfunc. Its functions compute brtf-model's {label} BSDF ({variant}
formulas) with the parameters at the light's theta_in. The real arguments are
constant diffuse parts (front and back reflectance, then transmittance), each the
smallest over theta_in; the functions add the rest."
            )));
            if shape.lobes > 1 {
                h.extend(lines(&format!(
                    "A lobe sum: the functions add the {} {kind} lobes with their weights at the
light's theta_in (a mixfunc coefficient cannot follow the light, so the lobes are
summed here, in one material).",
                    shape.lobes
                )));
            }
            if deltas {
                h.extend(lines(
                    "Roughness-0 incidences: the mirror (and straight-through) coefficients use the
parameters at the view's theta, as a mirror ray would see them.",
                ));
            }
            h.extend(lines(&format!(
                "
What differs from a static {label} in a rendering:
  - the specular lobe and the theta_in-dependent part of the diffuse term respond
    to light sources only; indirect light (-ab) reaches only the constant diffuse
    parts in the real arguments;
  - the lobe is not sampled: other objects do not appear in the glossy reflection
    (or transmission);"
            )));
            Primitive {
                modifier: "void".into(),
                kind: "BRTDfunc".into(),
                name: name.into(),
                strings,
                ints: Vec::new(),
                reals,
                line: 0,
            }
        }
    };
    h.extend(lines(
        "  - the reflected lobe is widened by the source size (omega/4pi) on every surface,
    where rtrace widens it on flat surfaces only, and -dj does not reduce it.

Reciprocity: the parameters follow the light's direction, so f(l, v) and f(v, l)
differ. Light sources play the role of the gonio-photometer's lamp; tools that
treat other surfaces as sources (mkillum) give theta_in from those.",
    ));
    h.push(String::new());
    h.extend(report::colour_line(result, colour));
    h.extend(report::verdict(result));
    if let Some(scale) = report::scale_caveat(result) {
        h.push(String::new());
        h.push(format!("Caveat: {scale}"));
    }
    if variant != Variant::Radiance {
        h.extend(lines(&format!(
            "
Variant {variant}: the functions evaluate the {variant} formulas that were fitted,
not what rtrace computes for a static {label} with the same parameters."
        )));
    }
    h.push(String::new());
    h.push(format!(
        "Same identifier as {static_file}: give oconv one or the other."
    ));
    let mut rad = comment_block(&h);
    rad += &format_primitive(&primitive);
    Ok(Theta { rad, cal, notes })
}

/// The lines of a text block.
fn lines(text: &str) -> Vec<String> {
    text.lines().map(str::to_string).collect()
}

/// Every table row must be a valid material of the table's shape.
fn check_rows(table: &ParamTable) -> Result<(), ExportError> {
    for (theta, args) in table.theta_in.iter().zip(&table.args) {
        composite(table, args, *theta)?;
    }
    Ok(())
}

/// The material of the table's shape with arguments `args` (of the row or
/// grid point at `theta`).
fn composite(table: &ParamTable, args: &[f64], theta: f64) -> Result<Composite, ExportError> {
    let material = |source| ExportError::Material {
        what: format!("the table row θ_in = {theta}"),
        kind: table.kind,
        source,
    };
    let shape = Shape::new(table.kind, table.lobes, table.oriented).map_err(ExportError::Table)?;
    Composite::new(shape, args, Some(DVec3::from_array(table.orientation))).map_err(material)
}

/// The interpolated materials on a fine θ_in grid (nodes included); for a
/// table that follows φ_in, on a (θ_in, φ_in) grid.
fn grid(table: &ParamTable) -> Result<Vec<Composite>, ExportError> {
    let (per_segment, azimuths) = if table.depends_on_azimuth() {
        (GRID_PER_SEGMENT_WITH_AZIMUTH, GRID_AZIMUTHS)
    } else {
        (GRID_PER_SEGMENT, 1)
    };
    let at = |t: f64, out: &mut Vec<Composite>| -> Result<(), ExportError> {
        for k in 0..azimuths {
            let phi = 360.0 * k as f64 / azimuths as f64;
            out.push(composite(table, &table.args_at_direction(t, phi).0, t)?);
        }
        Ok(())
    };
    let mut out = Vec::new();
    for w in table.theta_in.windows(2) {
        for j in 0..per_segment {
            at(
                w[0] + (w[1] - w[0]) * j as f64 / per_segment as f64,
                &mut out,
            )?;
        }
    }
    if let Some(&last) = table.theta_in.last() {
        at(last, &mut out)?;
    }
    Ok(out)
}

/// Indices of the transmissivity and transmitted-specular fraction.
fn trans_indices(kind: MaterialKind) -> (Option<usize>, Option<usize>) {
    match kind {
        MaterialKind::Trans => (Some(5), Some(6)),
        MaterialKind::Trans2 => (Some(6), Some(7)),
        _ => (None, None),
    }
}

/// True when every argument but the roughness is the same in every row.
fn only_roughness_varies(table: &ParamTable) -> bool {
    let first = &table.args[0];
    table
        .shape()
        .param_names()
        .iter()
        .enumerate()
        .all(|(j, name)| {
            name.starts_with("rough")
                || table
                    .args
                    .iter()
                    .all(|row| (row[j] - first[j]).abs() <= 1e-12 * first[j].abs().max(1.0))
        })
}

/// The smallest diffuse reflectance and transmittance (per channel) over
/// θ_in and over every view, times a small margin: the constant parts of
/// the `BRTDfunc`. A lobe sum's is the weighted sum of its primitives'.
fn diffuse_floor(variant: Variant, grid: &[Composite]) -> ([f64; 3], [f64; 3]) {
    let mut rd = [f64::INFINITY; 3];
    let mut td = [f64::INFINITY; 3];
    for material in grid {
        let mut r = [0.0; 3];
        let mut t = [0.0; 3];
        for (w, m) in material.components() {
            let (rm, tm) = primitive_diffuse_floor(m.kind(), variant, m.args());
            for k in 0..3 {
                r[k] += w * rm[k];
                t[k] += w * tm[k];
            }
        }
        for k in 0..3 {
            rd[k] = rd[k].min(r[k]);
            td[k] = td[k].min(t[k]);
        }
    }
    let finish = |x: [f64; 3]| {
        x.map(|v| {
            if v.is_finite() {
                (v * FLOOR_MARGIN).max(0.0)
            } else {
                0.0
            }
        })
    };
    (finish(rd), finish(td))
}

/// The smallest diffuse reflectance and transmittance of one primitive
/// with real arguments `a` over every view.
fn primitive_diffuse_floor(
    kind: MaterialKind,
    variant: Variant,
    a: &[f64],
) -> ([f64; 3], [f64; 3]) {
    // The view-dependent Fresnel terms are largest at the clamped view cosine.
    let e6 = (-6.0f64 * 0.001).exp();
    let (it, its) = trans_indices(kind);
    {
        let c = [a[0], a[1], a[2]];
        let rs = a[3];
        let pure = !kind.is_anisotropic() && a[4] * a[4] <= FTINY;
        let (r, t) = if variant == Variant::Radiance && pure && rs >= FRESNEL_THRESHOLD {
            // The Fresnel factors reach ~0 at grazing angles.
            ([0.0; 3], [0.0; 3])
        } else if variant == Variant::Ward1992 && kind.is_metal() {
            (
                c.map(|ck| ck * (1.0 - (ck * rs + (1.0 - ck * rs) * e6))),
                [0.0; 3],
            )
        } else {
            let s = if variant == Variant::Ward1992 {
                rs + e6 * (1.0 - rs)
            } else {
                rs
            };
            let trans = it.map_or(0.0, |i| a[i] * (1.0 - s));
            let tspec = its.map_or(0.0, |i| a[i]);
            let r_d = 1.0 - trans - s;
            let t_d = trans * (1.0 - tspec);
            let r_on = r_d > FTINY && trans < 1.0 - FTINY;
            let t_on = t_d > FTINY && trans > FTINY;
            (
                c.map(|ck| if r_on { ck * r_d } else { 0.0 }),
                c.map(|ck| if t_on { ck * t_d } else { 0.0 }),
            )
        };
        (r, t)
    }
}
