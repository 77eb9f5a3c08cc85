//! Materials as the tracer uses them: brtf-model's BSDF, split into the
//! parts of Radiance's equation (1), and the lobes to sample.
//!
//! A [`Shader`] is either one material or a θ_in-dependent material from
//! a fit's [`ParamTable`]. A material is a [`Composite`]: one primitive,
//! or a lobe sum of primitives mixed with constant weights `w_k`, shaded
//! as rtrace shades a constant `mixfunc` tree, term by term the weighted
//! sum `f = Σ w_k f_k` (the direct term, the diffuse part and the
//! specular part alike); the specular rays sample the lobes as a mixture
//! ([`crate::LobeMix`]). A one-primitive material is shaded exactly as
//! the primitive alone. A table material is evaluated with the
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
//!
//! ## Orientations
//!
//! The anisotropic types' frame has x along the material's orientation
//! vector projected on the surface (Radiance's `û`); the primitives of one
//! material share it (a mixture whose anisotropic primitives have
//! different vectors is refused). A table whose orientation angle is
//! fitted (`orient`) turns with θ_in: its materials are shaded in the
//! frame of one reference angle (the middle of the table's range) with
//! each grid material's orientation turned by its own angle from it, in
//! the tangent plane. On the flat sample of the gonio-photometer (normal
//! +z) that is exactly Radiance's projection of `(cos ψ, sin ψ, 0)`; on a
//! curved surface it is the same turn about the normal.

use brtf_fit::{ParamTable, TableError};
use brtf_model::{
    Bsdf, Composite, EvalOptions, FTINY, Material, MaterialKind, Rgb, ShapeArg, Variant,
    orientation_of_angle,
};
use glam::DVec3;

use crate::frame::Frame;
use crate::sampling::{LobeMix, Mixture, ReflectionLobe, TransmissionLobe};

/// Grid step (degrees) of a θ_in-table shader.
pub(crate) const TABLE_STEP_DEG: f64 = 0.25;

/// Grid steps (degrees) in θ_in and φ_in of a table that follows φ_in.
pub(crate) const AZIMUTH_GRID_STEP_DEG: (f64, f64) = (1.0, 2.5);

/// rtrace clamps the view cosine (`pdot >= .001`).
const MIN_VIEW_COSINE: f64 = 0.001;

/// What the view direction alone decides: which lobes exist and how to
/// sample them.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Lobes<'a> {
    /// The rough reflected lobes, if the material has any.
    pub reflect: Option<LobeMix<'a, ReflectionLobe>>,
    /// The rough transmitted lobes, if any.
    pub transmit: Option<LobeMix<'a, TransmissionLobe>>,
    /// Roughness 0: mirror and straight-through delta coefficients (the
    /// weighted sum over the roughness-0 primitives).
    pub delta: Option<(Rgb, Rgb)>,
    /// A diffuse reflection part exists.
    pub diffuse_reflect: bool,
    /// A diffuse transmission part exists.
    pub diffuse_transmit: bool,
}

/// One primitive's [`Lobes`].
struct PrimitiveLobes {
    reflect: Option<ReflectionLobe>,
    transmit: Option<TransmissionLobe>,
    delta: Option<(Rgb, Rgb)>,
    diffuse_reflect: bool,
    diffuse_transmit: bool,
}

/// One primitive prepared for shading.
#[derive(Debug, Clone)]
struct Primitive {
    /// Built with the orientation along local x (or turned from it, for a
    /// table's fitted orientation).
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

impl Primitive {
    /// `material` in the shading frame, its orientation vector there
    /// being `local` (x unless a table turns it).
    fn new(material: &Material, local: DVec3, options: &EvalOptions) -> Primitive {
        let kind = material.kind();
        let args = material.args();
        let along = Material::new(kind, args, Some(local)).expect("valid material");
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
        Primitive {
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

    fn lobes(&self, v: DVec3, degenerate: bool) -> PrimitiveLobes {
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
        PrimitiveLobes {
            reflect: (!pure && spec_on && reflecting).then_some(ReflectionLobe { wu, wv }),
            transmit: (!pure && ts > FTINY && transmitting)
                .then_some(TransmissionLobe { beta: wu.max(wv) }),
            delta: pure.then(|| self.bsdf.delta_coefficients(view_cosine)),
            diffuse_reflect: reflecting && (rd > FTINY || ward_metal),
            diffuse_transmit: transmitting && t - ts > FTINY,
        }
    }
}

/// The least share of a lobe's specularity in picking it from a mixture
/// (a spec-0 lobe still has a lobe under Ward 1992's Fresnel term).
const MIN_PICK_SPEC: f64 = 0.02;

/// One material prepared for shading: its primitives and their weights.
#[derive(Debug, Clone)]
struct Entry {
    /// The first primitive (the only one of a single primitive), kept
    /// inline: one primitive shades as it did alone.
    first: Primitive,
    /// The rest of a lobe sum.
    sum: Option<Box<LobeSum>>,
}

/// What a lobe sum adds to its first primitive.
#[derive(Debug, Clone)]
struct LobeSum {
    /// The first primitive's weight.
    first_weight: f64,
    /// The other primitives, `(w_k, primitive k)`; the weights sum to 1.
    rest: Vec<(f64, Primitive)>,
    /// The rough lobes as mixtures, for the orientation off and along the
    /// normal (`[normal, degenerate]`).
    reflect: [Option<Mixture<ReflectionLobe>>; 2],
    transmit: [Option<Mixture<TransmissionLobe>>; 2],
}

/// The rough lobes of the primitives of weight > 0 as a mixture, each
/// picked with probability ∝ `w_k × energy`, `lobe(primitive, (α_u²,
/// α_v²))` giving `(energy, lobe)`.
fn mixture<T: crate::DirectionSampler>(
    parts: &[(f64, &Primitive)],
    degenerate: bool,
    lobe: impl Fn(&Primitive, (f64, f64)) -> (f64, T),
) -> Option<Mixture<T>> {
    let weighted: Vec<(f64, T)> = parts
        .iter()
        .filter(|(w, p)| *w > 0.0 && !p.bsdf.is_pure())
        .map(|(w, p)| {
            let (wu, wv) = p.alpha2;
            let widths = if degenerate {
                (0.5 * (wu + wv), 0.5 * (wu + wv))
            } else {
                (wu, wv)
            };
            let (energy, lobe) = lobe(p, widths);
            (w * energy, lobe)
        })
        .collect();
    Mixture::new(&weighted)
}

impl Entry {
    /// `material` in a frame whose x axis is the projection of
    /// `reference` (see the module docs on orientations).
    fn new(material: &Composite, reference: DVec3, options: &EvalOptions) -> Entry {
        let flat = Frame::from_z_and_x(DVec3::Z, reference).unwrap_or(Frame::WORLD);
        let mut parts = material.components().iter().map(|(w, m)| {
            let o = m.orientation();
            // The reference itself is x exactly (the one-material case).
            let local = if o == reference || !m.kind().is_anisotropic() {
                DVec3::X
            } else {
                flat.to_local(o)
            };
            (*w, Primitive::new(m, local, options))
        });
        let (first_weight, first) = parts.next().expect("a material has a primitive");
        let rest: Vec<(f64, Primitive)> = parts.collect();
        if rest.is_empty() {
            return Entry { first, sum: None };
        }
        let all: Vec<(f64, &Primitive)> = std::iter::once((first_weight, &first))
            .chain(rest.iter().map(|(w, p)| (*w, p)))
            .collect();
        let reflect = |degenerate| {
            mixture(&all, degenerate, |p, (wu, wv)| {
                (p.spec.max(MIN_PICK_SPEC), ReflectionLobe { wu, wv })
            })
        };
        let transmit = |degenerate| {
            mixture(&all, degenerate, |p, (wu, wv)| {
                let trans = match p.kind {
                    MaterialKind::Trans => p.bsdf.material().args()[5],
                    MaterialKind::Trans2 => p.bsdf.material().args()[6],
                    _ => 0.0,
                };
                let energy = trans * p.tspec;
                let pick = if energy > 0.0 {
                    energy.max(MIN_PICK_SPEC)
                } else {
                    0.0
                };
                (pick, TransmissionLobe { beta: wu.max(wv) })
            })
        };
        let (reflect, transmit) = (
            [reflect(false), reflect(true)],
            [transmit(false), transmit(true)],
        );
        let sum = LobeSum {
            first_weight,
            rest,
            reflect,
            transmit,
        };
        Entry {
            first,
            sum: Some(Box::new(sum)),
        }
    }

    /// Every primitive with its weight.
    fn parts(&self) -> impl Iterator<Item = (f64, &Primitive)> {
        let (first_weight, rest) = match &self.sum {
            Some(sum) => (sum.first_weight, sum.rest.as_slice()),
            None => (1.0, &[][..]),
        };
        std::iter::once((first_weight, &self.first)).chain(rest.iter().map(|(w, p)| (*w, p)))
    }

    /// `Σ w_k value(k)`; one primitive's value as it is.
    #[inline]
    fn weighted(&self, value: impl Fn(&Primitive) -> Rgb) -> Rgb {
        if self.sum.is_none() {
            return value(&self.first);
        }
        let mut sum = [0.0; 3];
        for (w, p) in self.parts() {
            let f = value(p);
            for k in 0..3 {
                sum[k] += w * f[k];
            }
        }
        sum
    }

    /// `f`: the weighted sum (kept out of line, so that the one-primitive
    /// path of [`Shader::eval`] stays small).
    #[inline(never)]
    fn eval(&self, l: DVec3, v: DVec3, degenerate: bool) -> Rgb {
        self.weighted(|p| p.bsdf(degenerate).eval(l, v))
    }

    /// `f_d`: the weighted sum (out of line, as [`Self::eval`]).
    #[inline(never)]
    fn diffuse(&self, l: DVec3, v: DVec3) -> Rgb {
        self.weighted(|p| p.diffuse(l, v))
    }

    fn is_pure(&self) -> bool {
        self.parts().any(|(_, p)| p.bsdf.is_pure())
    }

    /// The lobes of the first primitive alone (all of one primitive's).
    #[inline]
    fn first_lobes(&self, v: DVec3, degenerate: bool) -> Lobes<'_> {
        let one = self.first.lobes(v, degenerate);
        Lobes {
            reflect: one.reflect.map(LobeMix::One),
            transmit: one.transmit.map(LobeMix::One),
            delta: one.delta,
            diffuse_reflect: one.diffuse_reflect,
            diffuse_transmit: one.diffuse_transmit,
        }
    }

    /// The lobes for view `v`: one primitive's own; for several, the
    /// mixtures of their rough lobes when any is on for this view, the
    /// weighted sum of their deltas, and the diffuse parts of any (out of
    /// line: the tracer's one-primitive path stays small).
    #[inline(never)]
    fn lobes(&self, v: DVec3, degenerate: bool) -> Lobes<'_> {
        let Some(mixtures) = &self.sum else {
            return self.first_lobes(v, degenerate);
        };
        let (mut reflect, mut transmit) = (false, false);
        let mut delta: Option<(Rgb, Rgb)> = None;
        let (mut diffuse_reflect, mut diffuse_transmit) = (false, false);
        for (w, p) in self.parts() {
            if w <= 0.0 {
                continue;
            }
            let one = p.lobes(v, degenerate);
            reflect |= one.reflect.is_some();
            transmit |= one.transmit.is_some();
            if let Some((mirror, through)) = one.delta {
                let (m, t) = delta.get_or_insert(([0.0; 3], [0.0; 3]));
                for k in 0..3 {
                    m[k] += w * mirror[k];
                    t[k] += w * through[k];
                }
            }
            diffuse_reflect |= one.diffuse_reflect;
            diffuse_transmit |= one.diffuse_transmit;
        }
        let i = usize::from(degenerate);
        Lobes {
            reflect: mixtures.reflect[i]
                .as_ref()
                .filter(|_| reflect)
                .map(LobeMix::Many),
            transmit: mixtures.transmit[i]
                .as_ref()
                .filter(|_| transmit)
                .map(LobeMix::Many),
            delta,
            diffuse_reflect,
            diffuse_transmit,
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
    /// Anisotropic primitives with different orientation vectors.
    #[error(
        "the anisotropic primitives of a mixture have different orientation vectors \
         ({} {} {} and {} {} {}): brtf-trace renders mixtures of one orientation",
        .0[0], .0[1], .0[2], .1[0], .1[1], .1[2]
    )]
    Orientations([f64; 3], [f64; 3]),
}

/// A material ready for shading: one material or a θ_in table.
#[derive(Debug, Clone)]
pub struct Shader {
    entries: Vec<Entry>,
    /// `Some(step)` for a table shader.
    step: Option<f64>,
    /// The orientation vector whose projection is the frame's x axis.
    orientation: DVec3,
    anisotropic: bool,
    transmitting: bool,
    options: EvalOptions,
    /// Some entry has roughness 0 (mirror and straight-through deltas).
    has_delta: bool,
    /// Every entry is a lobe sum (else every one is one primitive, shaded
    /// through its first primitive without looking at the rest).
    lobe_sum: bool,
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

/// The orientation shared by the anisotropic primitives of `material`
/// (its own vector when it has none), or why there is none.
fn shared_orientation(material: &Composite) -> Result<DVec3, ShaderError> {
    let mut oriented = material
        .components()
        .iter()
        .map(|(_, m)| m)
        .filter(|m| m.kind().is_anisotropic())
        .map(|m| m.orientation());
    let Some(first) = oriented.next() else {
        return Ok(material.orientation());
    };
    match oriented.find(|o| *o != first) {
        Some(other) => Err(ShaderError::Orientations(
            first.to_array(),
            other.to_array(),
        )),
        None => Ok(first),
    }
}

impl Shader {
    /// One material (one primitive or a lobe sum). `options.source_omega`
    /// is ignored (set to 0): sources are integrated by sampling.
    pub fn new(material: &Composite, options: &EvalOptions) -> Result<Shader, ShaderError> {
        let options = point_options(options);
        let orientation = shared_orientation(material)?;
        let entry = Entry::new(material, orientation, &options);
        Ok(Shader {
            has_delta: entry.is_pure(),
            lobe_sum: entry.sum.is_some(),
            entries: vec![entry],
            step: None,
            orientation,
            anisotropic: any_part(material, MaterialKind::is_anisotropic),
            transmitting: any_part(material, MaterialKind::is_transmitting),
            options,
            azimuth: None,
        })
    }

    /// A θ_in-dependent material from a fit's parameter table (of any
    /// shape: lobe sums, fitted orientations).
    pub fn from_table(table: &ParamTable, options: &EvalOptions) -> Result<Shader, ShaderError> {
        let options = point_options(options);
        let reference = table_reference(table);
        let prepare = |material: &Composite| -> Result<Entry, ShaderError> {
            shared_orientation(material)?;
            Ok(Entry::new(material, reference, &options))
        };
        let n = (90.0 / TABLE_STEP_DEG).round() as usize;
        let entries = (0..=n)
            .map(|i| prepare(&table.composite_at(i as f64 * TABLE_STEP_DEG)?.0))
            .collect::<Result<Vec<_>, ShaderError>>()?;
        let azimuth = if table.depends_on_azimuth() {
            let (theta_step, phi_step) = AZIMUTH_GRID_STEP_DEG;
            let rows = (90.0 / theta_step).round() as usize + 1;
            let columns = (360.0 / phi_step).round() as usize;
            let entries = (0..rows * columns)
                .map(|k| {
                    let theta = (k / columns) as f64 * theta_step;
                    let phi = (k % columns) as f64 * phi_step;
                    prepare(&table.composite_at_direction(theta, phi)?.0)
                })
                .collect::<Result<Vec<_>, ShaderError>>()?;
            Some(AzimuthGrid { entries, columns })
        } else {
            None
        };
        Ok(Shader {
            has_delta: entries.iter().any(Entry::is_pure)
                || azimuth
                    .as_ref()
                    .is_some_and(|g| g.entries.iter().any(Entry::is_pure)),
            entries,
            step: Some(TABLE_STEP_DEG),
            lobe_sum: table.lobes > 1,
            orientation: reference,
            anisotropic: table.kind.is_anisotropic(),
            transmitting: table.kind.is_transmitting(),
            options,
            azimuth,
        })
    }

    /// The material type (of the first primitive of a mixture).
    pub fn kind(&self) -> MaterialKind {
        self.entries[0].first.kind
    }

    /// True when some primitive is anisotropic (the frame follows the
    /// orientation).
    pub fn is_anisotropic(&self) -> bool {
        self.anisotropic
    }

    /// True when some primitive transmits light.
    pub fn is_transmitting(&self) -> bool {
        self.transmitting
    }

    /// Primitives per material: 1, or a lobe sum's lobes.
    pub fn lobe_count(&self) -> usize {
        self.entries[0].parts().count()
    }

    /// True if the material (or some θ_in of a table) has roughness 0, so
    /// [`Self::lobes`] can give delta coefficients.
    pub fn has_delta(&self) -> bool {
        self.has_delta
    }

    /// The one BSDF of a one-primitive, single-material shader (`None`
    /// for a table or a lobe sum), for batch evaluation: [`Self::eval`]
    /// with `degenerate = false` is this BSDF's `eval`.
    pub(crate) fn single_bsdf(&self) -> Option<&Bsdf> {
        let entry = &self.entries[0];
        (self.step.is_none() && entry.sum.is_none()).then_some(&entry.first.bsdf)
    }

    /// The primitives of a single-material shader with their weights
    /// (`None` for a table), for batch evaluation: [`Self::eval`] with
    /// `degenerate = false` is `Σ w_k eval_k`, added up in this order.
    pub(crate) fn part_bsdfs(&self) -> Option<impl Iterator<Item = (f64, &Bsdf)>> {
        self.step
            .is_none()
            .then(|| self.entries[0].parts().map(|(w, p)| (w, &p.bsdf)))
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

    /// The whole BSDF `f(l, v)` (1/sr, no cosine), local frame: the
    /// weighted sum of the primitives'.
    #[inline]
    pub fn eval(&self, l: DVec3, v: DVec3, degenerate: bool) -> Rgb {
        if let (Some(grid), false) = (&self.azimuth, degenerate) {
            return grid.mix(l, |e| self.entry_eval(e, l, v, false));
        }
        let (i, j, t) = self.blend(l.z);
        let a = self.entry_eval(&self.entries[i], l, v, degenerate);
        if t == 0.0 {
            return a;
        }
        let b = self.entry_eval(&self.entries[j], l, v, degenerate);
        std::array::from_fn(|k| a[k] + t * (b[k] - a[k]))
    }

    /// The diffuse part `f_d(l, v)` of [`Self::eval`] (`v.z ≥ 0`): the
    /// weighted sum of the primitives' diffuse parts.
    #[inline]
    pub fn diffuse(&self, l: DVec3, v: DVec3) -> Rgb {
        if let Some(grid) = &self.azimuth {
            return grid.mix(l, |e| self.entry_diffuse(e, l, v));
        }
        let (i, j, t) = self.blend(l.z);
        let a = self.entry_diffuse(&self.entries[i], l, v);
        if t == 0.0 {
            return a;
        }
        let b = self.entry_diffuse(&self.entries[j], l, v);
        std::array::from_fn(|k| a[k] + t * (b[k] - a[k]))
    }

    /// `f` of one grid material.
    #[inline(always)]
    fn entry_eval(&self, e: &Entry, l: DVec3, v: DVec3, degenerate: bool) -> Rgb {
        if self.lobe_sum {
            e.eval(l, v, degenerate)
        } else {
            e.first.bsdf(degenerate).eval(l, v)
        }
    }

    /// `f_d` of one grid material.
    #[inline(always)]
    fn entry_diffuse(&self, e: &Entry, l: DVec3, v: DVec3) -> Rgb {
        if self.lobe_sum {
            e.diffuse(l, v)
        } else {
            e.first.diffuse(l, v)
        }
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
    pub fn lobes(&self, v: DVec3, degenerate: bool) -> Lobes<'_> {
        let (i, j, t) = self.blend(v.z);
        let e = &self.entries[if t < 0.5 { i } else { j }];
        match self.lobe_sum {
            true => e.lobes(v, degenerate),
            false => e.first_lobes(v, degenerate),
        }
    }
}

/// True when some primitive of `material` is of a kind for which `test` holds.
fn any_part(material: &Composite, test: impl Fn(MaterialKind) -> bool) -> bool {
    material.components().iter().any(|(_, m)| test(m.kind()))
}

/// The orientation vector whose projection is a table shader's frame x:
/// the table's own, or for a fitted orientation (not following φ_in) the
/// middle of its angles' range.
fn table_reference(table: &ParamTable) -> DVec3 {
    let fitted = table
        .shape()
        .index_of(ShapeArg::Orient)
        .filter(|_| !table.depends_on_azimuth());
    match fitted {
        Some(o) => {
            let angles = table.args.iter().map(|row| row[o]);
            let lo = angles.clone().fold(f64::INFINITY, f64::min);
            let hi = angles.fold(f64::NEG_INFINITY, f64::max);
            orientation_of_angle(0.5 * (lo + hi))
        }
        None => DVec3::from_array(table.orientation),
    }
}

fn point_options(options: &EvalOptions) -> EvalOptions {
    EvalOptions {
        source_omega: 0.0,
        ..*options
    }
}
