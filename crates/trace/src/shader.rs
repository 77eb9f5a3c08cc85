//! Materials as the tracer uses them: brtf-model's BSDF, split into the
//! parts of Radiance's equation (1), and the lobes to sample.
//!
//! A [`Shader`] is either one material or a θ_in-dependent material from
//! a fit's [`ParamTable`]. A table material is evaluated with the
//! parameters at the **light's** polar angle θ_l = acos|l·n| (the
//! incidence of the measurement it was fitted to): the table is sampled
//! on a 0.25° grid once, and `f` is interpolated linearly between the two
//! neighbouring grid materials. A table that follows φ_in too (an
//! anisotropic type fitted to a Klems basis) is sampled on a 1° × 2.5°
//! (θ, φ) grid and interpolated bilinearly, with φ_l the light's azimuth
//! from u towards v = n × u, n the normal on the light's side
//! ([`brtf_fit::AzimuthRing`]). Where the orientation is along the normal
//! (no azimuth), the φ-averaged rows apply.
//!
//! The shader always evaluates the **point** BSDF (brtf-model with source
//! solid angle ω = 0): the tracer integrates over a source's solid angle
//! by sampling it, which is the physical counterpart of rtrace's lobe
//! widening `α² + ω/4π`.
//!
//! Equation (1) separates what comes from the sources (the direct term,
//! with the whole `f`) from what other rays bring: the specular rays
//! (`ρ_s R(m)`, `τ_s R(t)`) and the diffuse ambient (`ρ_a A/π`). For those
//! the shader splits `f = f_d + f_s`: [`Shader::diffuse`] is the diffuse
//! part `C R_d/π` (and `C T_d/π` behind), brtf-model's
//! [`Bsdf::eval_diffuse`]; `f_s = f − f_d`.

use brtf_fit::{ParamTable, TableError};
use brtf_model::{Bsdf, EvalOptions, FTINY, Material, MaterialKind, Rgb, Variant};
use glam::DVec3;

use crate::frame::Frame;
use crate::sampling::{ReflectionLobe, TransmissionLobe};

/// Grid step (degrees) of a θ_in-table shader.
pub(crate) const TABLE_STEP_DEG: f64 = 0.25;

/// Grid steps (degrees) in θ_in and φ_in of a table that follows φ_in.
pub(crate) const AZIMUTH_GRID_STEP_DEG: (f64, f64) = (1.0, 2.5);

/// rtrace clamps the view cosine (`pdot >= .001`).
const MIN_VIEW_COSINE: f64 = 0.001;

/// What the view direction alone decides: which lobes exist and how to
/// sample them.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Lobes {
    /// The rough reflected lobe, if the material has one.
    pub reflect: Option<ReflectionLobe>,
    /// The rough transmitted lobe, if any.
    pub transmit: Option<TransmissionLobe>,
    /// Roughness 0: mirror and straight-through delta coefficients.
    pub delta: Option<(Rgb, Rgb)>,
    /// A diffuse reflection part exists.
    pub diffuse_reflect: bool,
    /// A diffuse transmission part exists.
    pub diffuse_transmit: bool,
}

/// One material prepared for shading.
#[derive(Debug, Clone)]
struct Entry {
    /// Built with the orientation along local x.
    bsdf: Bsdf,
    /// Anisotropic types only: built with the orientation along the
    /// normal (rtrace's arbitrary tangent and mean roughness).
    degenerate: Option<Bsdf>,
    kind: MaterialKind,
    /// The specularity argument (before any Fresnel estimate).
    spec: f64,
    tspec: f64,
    alpha2: (f64, f64),
    variant: Variant,
}

impl Entry {
    fn new(material: &Material, options: &EvalOptions) -> Entry {
        let kind = material.kind();
        let args = material.args();
        let along = Material::new(kind, args, Some(DVec3::X)).expect("valid material");
        let degenerate = kind
            .is_anisotropic()
            .then(|| Material::new(kind, args, Some(DVec3::Z)).expect("valid material"));
        let tspec = match kind {
            MaterialKind::Trans => args[6],
            MaterialKind::Trans2 => args[7],
            _ => 0.0,
        };
        let alpha2 = if kind.is_anisotropic() {
            (args[4] * args[4], args[5] * args[5])
        } else {
            (args[4] * args[4], args[4] * args[4])
        };
        Entry {
            bsdf: Bsdf::new(&along, options),
            degenerate: degenerate.map(|m| Bsdf::new(&m, options)),
            kind,
            spec: material.spec(),
            tspec,
            alpha2,
            variant: options.variant,
        }
    }

    #[inline]
    fn bsdf(&self, degenerate: bool) -> &Bsdf {
        match (&self.degenerate, degenerate) {
            (Some(b), true) => b,
            _ => &self.bsdf,
        }
    }

    /// The diffuse part of `f(l, v)`, `v.z ≥ 0`.
    #[inline]
    fn diffuse(&self, l: DVec3, v: DVec3) -> Rgb {
        self.bsdf.eval_diffuse(l, v)
    }

    fn lobes(&self, v: DVec3, degenerate: bool) -> Lobes {
        let view_cosine = v.z.max(MIN_VIEW_COSINE);
        let split = self.bsdf.view_split(view_cosine);
        let (spec, t, rd) = (split.spec, split.transmitted, split.diffuse);
        let ts = t * self.tspec;
        let (mut wu, mut wv) = self.alpha2;
        if degenerate {
            let mean = 0.5 * (wu + wv);
            (wu, wv) = (mean, mean);
        }
        let ward_metal = self.kind.is_metal() && self.variant == Variant::Ward1992;
        let spec_on = if ward_metal {
            self.spec > FTINY
        } else {
            spec > FTINY
        };
        let pure = self.bsdf.is_pure();
        let reflecting = t < 1.0 - FTINY;
        let transmitting = t > FTINY;
        Lobes {
            reflect: (!pure && spec_on && reflecting).then_some(ReflectionLobe { wu, wv }),
            transmit: (!pure && ts > FTINY && transmitting)
                .then_some(TransmissionLobe { beta: wu.max(wv) }),
            delta: pure.then(|| self.bsdf.delta_coefficients(view_cosine)),
            diffuse_reflect: reflecting && (rd > FTINY || ward_metal),
            diffuse_transmit: transmitting && t - ts > FTINY,
        }
    }
}

/// Why a shader could not be built.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum ShaderError {
    /// The fit's θ_in table gives an invalid material somewhere.
    #[error("θ_in table: {0}")]
    Table(#[from] TableError),
}

/// A material ready for shading: one material or a θ_in table.
#[derive(Debug, Clone)]
pub struct Shader {
    entries: Vec<Entry>,
    /// `Some(step)` for a table shader.
    step: Option<f64>,
    orientation: DVec3,
    anisotropic: bool,
    options: EvalOptions,
    /// Some entry has roughness 0 (mirror and straight-through deltas).
    has_delta: bool,
    /// A table that follows φ_in: its (θ, φ) grid.
    azimuth: Option<AzimuthGrid>,
}

/// The materials of a (θ_in, φ_in) table on a regular grid.
#[derive(Debug, Clone)]
struct AzimuthGrid {
    /// Row-major: θ rows of `columns` azimuths.
    entries: Vec<Entry>,
    columns: usize,
}

impl AzimuthGrid {
    /// The four neighbouring grid materials of a light `l` (local frame)
    /// and their bilinear weights.
    #[inline]
    fn blend(&self, l: DVec3) -> [(usize, f64); 4] {
        let (theta_step, phi_step) = AZIMUTH_GRID_STEP_DEG;
        let rows = self.entries.len() / self.columns;
        let theta = l.z.abs().min(1.0).acos().to_degrees();
        let x = (theta / theta_step).min((rows - 1) as f64);
        let i = (x.floor() as usize).min(rows - 2);
        let t = x - i as f64;
        // Azimuth in the frame whose normal is on the light's side.
        let phi = (l.z.signum() * l.y)
            .atan2(l.x)
            .to_degrees()
            .rem_euclid(360.0);
        let y = phi / phi_step;
        let c = (y.floor() as usize) % self.columns;
        let s = y - y.floor();
        let d = (c + 1) % self.columns;
        let at = |row: usize, col: usize| row * self.columns + col;
        [
            (at(i, c), (1.0 - t) * (1.0 - s)),
            (at(i, d), (1.0 - t) * s),
            (at(i + 1, c), t * (1.0 - s)),
            (at(i + 1, d), t * s),
        ]
    }

    #[inline]
    fn mix(&self, l: DVec3, value: impl Fn(&Entry) -> Rgb) -> Rgb {
        let mut sum = [0.0; 3];
        for (e, w) in self.blend(l) {
            if w != 0.0 {
                let f = value(&self.entries[e]);
                for k in 0..3 {
                    sum[k] += w * f[k];
                }
            }
        }
        sum
    }
}

impl Shader {
    /// One material. `options.source_omega` is ignored (set to 0): sources
    /// are integrated by sampling.
    pub fn new(material: &Material, options: &EvalOptions) -> Shader {
        let options = point_options(options);
        let entry = Entry::new(material, &options);
        Shader {
            has_delta: entry.bsdf.is_pure(),
            entries: vec![entry],
            step: None,
            orientation: material.orientation(),
            anisotropic: material.kind().is_anisotropic(),
            options,
            azimuth: None,
        }
    }

    /// A θ_in-dependent material from a fit's parameter table.
    pub fn from_table(table: &ParamTable, options: &EvalOptions) -> Result<Shader, ShaderError> {
        let options = point_options(options);
        let n = (90.0 / TABLE_STEP_DEG).round() as usize;
        let entries = (0..=n)
            .map(|i| {
                let lookup = table.at(i as f64 * TABLE_STEP_DEG)?;
                Ok(Entry::new(&lookup.material, &options))
            })
            .collect::<Result<Vec<_>, TableError>>()?;
        let azimuth = if table.depends_on_azimuth() {
            let (theta_step, phi_step) = AZIMUTH_GRID_STEP_DEG;
            let rows = (90.0 / theta_step).round() as usize + 1;
            let columns = (360.0 / phi_step).round() as usize;
            let entries = (0..rows * columns)
                .map(|k| {
                    let theta = (k / columns) as f64 * theta_step;
                    let phi = (k % columns) as f64 * phi_step;
                    let lookup = table.at_direction(theta, phi)?;
                    Ok(Entry::new(&lookup.material, &options))
                })
                .collect::<Result<Vec<_>, TableError>>()?;
            Some(AzimuthGrid { entries, columns })
        } else {
            None
        };
        Ok(Shader {
            has_delta: entries.iter().any(|e| e.bsdf.is_pure())
                || azimuth
                    .as_ref()
                    .is_some_and(|g| g.entries.iter().any(|e| e.bsdf.is_pure())),
            entries,
            step: Some(TABLE_STEP_DEG),
            orientation: DVec3::from_array(table.orientation),
            anisotropic: table.kind.is_anisotropic(),
            options,
            azimuth,
        })
    }

    /// The material type.
    pub fn kind(&self) -> MaterialKind {
        self.entries[0].kind
    }

    /// True if the material (or some θ_in of a table) has roughness 0, so
    /// [`Self::lobes`] can give delta coefficients.
    pub fn has_delta(&self) -> bool {
        self.has_delta
    }

    /// The one BSDF of a single-material shader (`None` for a table),
    /// for batch evaluation: [`Self::eval`] with `degenerate = false` is
    /// this BSDF's `eval`.
    pub(crate) fn single_bsdf(&self) -> Option<&Bsdf> {
        self.step.is_none().then(|| &self.entries[0].bsdf)
    }

    /// True for a θ_in-table shader.
    pub fn is_table(&self) -> bool {
        self.step.is_some()
    }

    /// The evaluation options (always with ω = 0).
    pub fn options(&self) -> &EvalOptions {
        &self.options
    }

    /// The shading frame at a surface point with unit normal `n` already
    /// turned towards the viewer, and whether it is rtrace's degenerate
    /// anisotropic case (orientation along the normal).
    #[inline]
    pub fn frame(&self, n: DVec3) -> (Frame, bool) {
        if self.anisotropic {
            match Frame::from_z_and_x(n, self.orientation) {
                Some(f) => (f, false),
                None => (Frame::from_z(n), true),
            }
        } else {
            (Frame::from_z(n), false)
        }
    }

    /// Grid entries and weights for a light at polar cosine `cos_l`.
    #[inline]
    fn blend(&self, cos_l: f64) -> (usize, usize, f64) {
        match self.step {
            None => (0, 0, 0.0),
            Some(step) => {
                let theta = cos_l.abs().min(1.0).acos().to_degrees();
                let x = (theta / step).min((self.entries.len() - 1) as f64);
                let i = (x.floor() as usize).min(self.entries.len() - 2);
                (i, i + 1, x - i as f64)
            }
        }
    }

    /// The whole BSDF `f(l, v)` (1/sr, no cosine), local frame.
    #[inline]
    pub fn eval(&self, l: DVec3, v: DVec3, degenerate: bool) -> Rgb {
        if let (Some(grid), false) = (&self.azimuth, degenerate) {
            return grid.mix(l, |e| e.bsdf(false).eval(l, v));
        }
        let (i, j, t) = self.blend(l.z);
        let a = self.entries[i].bsdf(degenerate).eval(l, v);
        if t == 0.0 {
            return a;
        }
        let b = self.entries[j].bsdf(degenerate).eval(l, v);
        std::array::from_fn(|k| a[k] + t * (b[k] - a[k]))
    }

    /// The diffuse part `f_d(l, v)` of [`Self::eval`] (`v.z ≥ 0`).
    #[inline]
    pub fn diffuse(&self, l: DVec3, v: DVec3) -> Rgb {
        if let Some(grid) = &self.azimuth {
            return grid.mix(l, |e| e.diffuse(l, v));
        }
        let (i, j, t) = self.blend(l.z);
        let a = self.entries[i].diffuse(l, v);
        if t == 0.0 {
            return a;
        }
        let b = self.entries[j].diffuse(l, v);
        std::array::from_fn(|k| a[k] + t * (b[k] - a[k]))
    }

    /// The specular part `f − f_d` (clamped at 0 against rounding).
    #[inline]
    pub fn specular(&self, l: DVec3, v: DVec3, degenerate: bool) -> Rgb {
        let f = self.eval(l, v, degenerate);
        let d = self.diffuse(l, v);
        std::array::from_fn(|k| (f[k] - d[k]).max(0.0))
    }

    /// The lobes to sample for view `v` (`v.z ≥ 0`). A table shader uses
    /// the material at θ_l = θ_v, where the reflected lobe peaks.
    #[inline]
    pub fn lobes(&self, v: DVec3, degenerate: bool) -> Lobes {
        let (i, j, t) = self.blend(v.z);
        let e = if t < 0.5 { i } else { j };
        self.entries[e].lobes(v, degenerate)
    }
}

fn point_options(options: &EvalOptions) -> EvalOptions {
    EvalOptions {
        source_omega: 0.0,
        ..*options
    }
}
