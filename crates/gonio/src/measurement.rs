//! The in-memory measurement: one incidence, many scattered samples.
//!
//! This module owns the data model every other part of the crate reads and
//! writes: [`Measurement`], [`Sample`], [`Incidence`], [`Quantity`],
//! [`Channels`], the `.mpc`-only extras ([`MpcColumns`], [`BeamReference`])
//! and the "not available" sentinel rule. It does no I/O.
//!
//! Samples are stored as one `Vec<Sample>` of small `Copy` structs (56
//! bytes each) so a fitter can stream over 120 000 of them cheaply. Every
//! sample carries three value slots; a CIE-Y measurement uses slot 0 and
//! leaves slots 1 and 2 at zero.

use glam::DVec3;
use serde::{Deserialize, Serialize};

/// The value gonio files use for "not available" (`9.9e+37`).
///
/// Readers turn any value with magnitude at or above [`SENTINEL_THRESHOLD`]
/// into `f64::NAN`; writers turn NaN back into this literal text.
pub const SENTINEL: f64 = 9.9e37;

/// Values with `|v| >= SENTINEL_THRESHOLD` are read as "not available".
///
/// No physical reading comes near this, so any spelling of the sentinel
/// (`9.9e+37`, `9.90000e37`, `1e38`) is caught.
pub const SENTINEL_THRESHOLD: f64 = 1.0e37;

/// The literal text writers emit for a NaN ("not available") value.
pub const SENTINEL_TEXT: &str = "9.9e+37";

/// The file format a measurement was read from (or is meant for).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum SourceFormat {
    /// Fraunhofer ISE `.mpc`: eight columns, BRTF in column 7, Voronoi cell
    /// sizes in column 8, incidence in label-then-value header pairs.
    Mpc,
    /// pab-opto "Mountain" (pgII): `theta phi value [value value]` rows with
    /// `#key value` header lines.
    Mountain,
    /// Klems BSDF XML (LBNL/WINDOW): each measurement is one incident
    /// patch of one side, and its values are **patch averages** (BSDF
    /// averaged over each outgoing patch), not point values. Read with
    /// [`crate::klems`]; not written by the gonio writers.
    KlemsXml,
}

brtf_model::option_words!(SourceFormat {
    Mpc => "mpc",
    Mountain => "mountain",
    KlemsXml => "klems-xml",
});

impl SourceFormat {
    /// The format's name, for people.
    pub fn describe(self) -> &'static str {
        match self {
            SourceFormat::Mpc => "ISE .mpc",
            SourceFormat::Mountain => "pab-opto Mountain",
            SourceFormat::KlemsXml => "Klems BSDF XML (patch averages)",
        }
    }
}

/// The incident direction, **towards the light source**, in degrees.
///
/// θ is measured from the front normal (θ > 90° means lit from the back);
/// φ is normalised to `[0, 360)` by the readers.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct Incidence {
    /// Polar angle θ_in from the front normal, degrees.
    pub theta_deg: f64,
    /// Azimuth φ_in, degrees, counter-clockwise seen from the front.
    pub phi_deg: f64,
}

impl Incidence {
    /// An incidence from θ_in and φ_in in degrees (stored as given).
    pub fn new(theta_deg: f64, phi_deg: f64) -> Self {
        Self { theta_deg, phi_deg }
    }

    /// Unit vector towards the light source, z = front normal.
    pub fn direction(&self) -> DVec3 {
        direction_from_degrees(self.theta_deg, self.phi_deg)
    }

    /// The mirror (specular) direction `(θ_in, φ_in + 180°)` as a unit vector.
    pub fn mirror_direction(&self) -> DVec3 {
        let d = self.direction();
        DVec3::new(-d.x, -d.y, d.z)
    }

    /// The straight-through direction `(180° − θ_in, φ_in + 180°)`.
    pub fn straight_through_direction(&self) -> DVec3 {
        -self.direction()
    }
}

/// Where the incidence of a measurement came from.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize, Default)]
#[serde(rename_all = "snake_case")]
pub enum IncidenceOrigin {
    /// Header lines of the file.
    Header,
    /// The file name (`…:+15+0.mpc`), because the header lacked it.
    FileName,
    /// Set by code (synthetic data, conversions).
    #[default]
    Programmatic,
}

/// What the sample values mean.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(tag = "kind", rename_all = "snake_case")]
pub enum Quantity {
    /// BSDF (BRDF in front, BTDF in back), radiance out ÷ irradiance in, 1/sr,
    /// without any cosine factor.
    Bsdf,
    /// "Distribution of scattered flux": BSDF × |cos θ_out|, 1/sr.
    Dsf,
    /// Raw detector signal in `unit` (e.g. `uA`), proportional to the DSF.
    /// `raw / beam_integral` is the DSF when the beam integral is known.
    Raw {
        /// The unit as written between brackets in the file, e.g. `uA`.
        unit: String,
        /// The beam (reference) integral in the same unit, when known.
        beam_integral: Option<f64>,
    },
}

impl Quantity {
    /// The unit of the values: `1/sr` for BSDF and DSF, the file's unit for raw.
    pub fn unit(&self) -> &str {
        match self {
            Quantity::Bsdf | Quantity::Dsf => "1/sr",
            Quantity::Raw { unit, .. } => unit,
        }
    }

    /// A short name: `BSDF`, `DSF` or `raw`.
    pub fn name(&self) -> &'static str {
        match self {
            Quantity::Bsdf => "BSDF",
            Quantity::Dsf => "DSF",
            Quantity::Raw { .. } => "raw",
        }
    }

    /// True when the values carry a factor |cos θ_out| (DSF and raw signal).
    pub fn includes_cosine(&self) -> bool {
        !matches!(self, Quantity::Bsdf)
    }
}

impl std::fmt::Display for Quantity {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            Quantity::Bsdf => f.write_str("BSDF [1/sr]"),
            Quantity::Dsf => f.write_str("DSF = BSDF x |cos theta_out| [1/sr]"),
            Quantity::Raw {
                unit,
                beam_integral: Some(b),
            } => write!(f, "raw detector signal [{unit}], beam integral {b}"),
            Quantity::Raw {
                unit,
                beam_integral: None,
            } => write!(f, "raw detector signal [{unit}], beam integral unknown"),
        }
    }
}

/// How many values each sample carries.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Serialize, Deserialize, Default)]
pub enum Channels {
    /// One value per sample: CIE-Y (photopic luminance). Stored in slot 0.
    #[default]
    #[serde(rename = "CIE-Y")]
    Y,
    /// Three values per sample: CIE X, Y, Z in slots 0, 1, 2.
    #[serde(rename = "CIE-XYZ")]
    Xyz,
}

// `rgb`: `brtf render gonio --channels rgb` writes the material's colour
// as CIE X, Y, Z.
brtf_model::option_words!(Channels { Y => "y", Xyz => "xyz" | "rgb" });

impl Channels {
    /// Number of values per sample (1 or 3).
    pub fn count(self) -> usize {
        match self {
            Channels::Y => 1,
            Channels::Xyz => 3,
        }
    }

    /// The slot holding CIE-Y: 0 for [`Channels::Y`], 1 for [`Channels::Xyz`].
    pub fn luminance_slot(self) -> usize {
        match self {
            Channels::Y => 0,
            Channels::Xyz => 1,
        }
    }

    /// The spelling used by the Mountain `#colorimetry:` header.
    pub fn colorimetry_name(self) -> &'static str {
        match self {
            Channels::Y => "CIE-Y",
            Channels::Xyz => "CIE-XYZ",
        }
    }
}

/// Front (θ ≤ 90°, reflection) or back (θ > 90°, transmission) hemisphere.
///
/// A sample at exactly θ = 90° counts as front. Its |cos θ| is zero, so it
/// adds nothing to either hemispherical integral.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Hemisphere {
    /// θ ≤ 90°.
    Front,
    /// θ > 90°.
    Back,
}

/// Which hemispheres a fit uses: one, or both.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Hemispheres {
    /// The front hemisphere (reflection).
    Front,
    /// The back hemisphere (transmission).
    Back,
    /// Both.
    Both,
}

brtf_model::option_words!(Hemispheres { Front => "front", Back => "back", Both => "both" });

impl Hemispheres {
    /// The one hemisphere kept, or `None` for both.
    pub fn only(self) -> Option<Hemisphere> {
        match self {
            Hemispheres::Front => Some(Hemisphere::Front),
            Hemispheres::Back => Some(Hemisphere::Back),
            Hemispheres::Both => None,
        }
    }
}

impl Hemisphere {
    /// The hemisphere a polar angle θ (degrees) falls in.
    pub fn of_theta(theta_deg: f64) -> Self {
        if theta_deg > 90.0 {
            Hemisphere::Back
        } else {
            Hemisphere::Front
        }
    }
}

/// One scattered direction (towards the detector) and its values.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct Sample {
    /// θ_out from the front normal, degrees, in `[0, 180]`.
    pub theta_deg: f64,
    /// φ_out, degrees, in `[0, 360)` after reading.
    pub phi_deg: f64,
    /// The values: slot 0 for CIE-Y data, slots 0..3 for CIE-XYZ. Unused
    /// slots are 0. NaN means "not available" (the file's `9.9e+37`).
    #[serde(with = "nan_as_null::array3")]
    pub values: [f64; 3],
    /// The solid angle this sample stands for (Voronoi cell size), sr.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub solid_angle_sr: Option<f64>,
}

impl Sample {
    /// A sample with all three value slots given and no solid angle.
    pub fn new(theta_deg: f64, phi_deg: f64, values: [f64; 3]) -> Self {
        Self {
            theta_deg,
            phi_deg,
            values,
            solid_angle_sr: None,
        }
    }

    /// A one-channel (CIE-Y) sample.
    pub fn luminance(theta_deg: f64, phi_deg: f64, value: f64) -> Self {
        Self::new(theta_deg, phi_deg, [value, 0.0, 0.0])
    }

    /// Unit vector towards the detector: `(sinθ cosφ, sinθ sinφ, cosθ)`.
    pub fn direction(&self) -> DVec3 {
        direction_from_degrees(self.theta_deg, self.phi_deg)
    }

    /// |cos θ_out|.
    pub fn abs_cos_theta(&self) -> f64 {
        brtf_model::cos_degrees(self.theta_deg).abs()
    }

    /// Which hemisphere the sample lies in.
    pub fn hemisphere(&self) -> Hemisphere {
        Hemisphere::of_theta(self.theta_deg)
    }

    /// True when every used value slot holds a finite number.
    pub fn is_available(&self, channels: Channels) -> bool {
        self.values[..channels.count()]
            .iter()
            .all(|v| v.is_finite())
    }
}

/// Unit vector `(sinθ cosφ, sinθ sinφ, cosθ)` for angles in degrees.
///
/// The same vector as [`brtf_model::direction`] (sines and cosines of the
/// degrees reduced exactly, see [`brtf_model::sin_cos_degrees`]).
pub fn direction_from_degrees(theta_deg: f64, phi_deg: f64) -> DVec3 {
    brtf_model::direction(theta_deg, phi_deg)
}

/// Normalises an azimuth in degrees to `[0, 360)`.
///
/// Both file conventions, `[0, 360)` and `(−180, 180]`, end up here; a value
/// already in range is returned bit-for-bit unchanged, so re-reading a
/// written file gives identical numbers.
pub fn normalize_phi_deg(phi_deg: f64) -> f64 {
    if (0.0..360.0).contains(&phi_deg) {
        return phi_deg;
    }
    // (−360, 0) is the common case, (−180, 180] files: the same single
    // rounding as `rem_euclid`, without its slow `fmod`.
    let wrapped = if (-360.0..0.0).contains(&phi_deg) {
        phi_deg + 360.0
    } else {
        phi_deg.rem_euclid(360.0)
    };
    // rem_euclid of a tiny negative number rounds up to exactly 360.
    if wrapped >= 360.0 { 0.0 } else { wrapped }
}

/// The four extra `.mpc` columns kept for a faithful round trip.
///
/// NaN means the file held the `9.9e+37` sentinel.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct MpcColumns {
    /// Column 3: beam reference reading.
    #[serde(with = "nan_as_null::scalar")]
    pub beam_reference: f64,
    /// Column 4: raw detector signal.
    #[serde(with = "nan_as_null::scalar")]
    pub raw_signal: f64,
    /// Column 5: background-subtracted signal ÷ beam reference.
    #[serde(with = "nan_as_null::scalar")]
    pub minus_background_per_beam_reference: f64,
    /// Column 6: column 5 ÷ |cos θ_out|.
    #[serde(with = "nan_as_null::scalar")]
    pub cosine_corrected: f64,
}

impl MpcColumns {
    /// All four columns "not available".
    pub const UNAVAILABLE: MpcColumns = MpcColumns {
        beam_reference: f64::NAN,
        raw_signal: f64::NAN,
        minus_background_per_beam_reference: f64::NAN,
        cosine_corrected: f64::NAN,
    };
}

/// The `.mpc` `#using beam file: NAME VALUE` header: the beam reference
/// integral the BRTF column was divided by.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct BeamReference {
    /// The beam file name, e.g. `pab-aluA-st1:beam.mpc.refint`.
    pub file: String,
    /// The beam reference integral.
    pub integral: f64,
}

/// One gonio-photometer scan: a single incidence and its scattered samples.
///
/// Build one programmatically with [`Measurement::new`] and set the public
/// fields; the readers fill every field from a file.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Measurement {
    /// The format the data came from (writers may target either).
    pub format: SourceFormat,
    /// `#sample_name` (Mountain), without quotes.
    #[serde(default)]
    pub sample_name: Option<String>,
    /// Incident direction (towards the light), degrees.
    pub incidence: Incidence,
    /// Where [`Measurement::incidence`] came from.
    #[serde(default)]
    pub incidence_origin: IncidenceOrigin,
    /// Mountain `#upphi`: the azimuth of the sample's "up" direction
    /// (default 0; Radiance's standard BSDF frame wants 90). Stored only,
    /// never applied to the sample azimuths.
    #[serde(default)]
    pub up_phi_deg: f64,
    /// What the values mean.
    pub quantity: Quantity,
    /// One (CIE-Y) or three (CIE-XYZ) values per sample.
    #[serde(default)]
    pub channels: Channels,
    /// The scattered samples, in file order.
    pub samples: Vec<Sample>,
    /// `.mpc` columns 3-6, parallel to `samples`; empty when not known.
    #[serde(default)]
    pub mpc_columns: Vec<MpcColumns>,
    /// `.mpc` beam reference (`#using beam file:`), when given.
    #[serde(default)]
    pub beam: Option<BeamReference>,
    /// Every header line of the source file, in order, without line ends.
    /// `.mpc` bare value lines (`30`) are header lines too.
    #[serde(default)]
    pub header: Vec<String>,
}

impl Measurement {
    /// The header's key/value pairs: `#key value` lines give `key → value`
    /// (quotes and tabs trimmed), `.mpc` `#label:` lines followed by a value
    /// line give `label → value`, in file order.
    pub fn header_pairs(&self) -> Vec<(String, String)> {
        let mut pairs = Vec::new();
        let mut label: Option<String> = None;
        for line in &self.header {
            let line = line.trim();
            let Some(body) = line.strip_prefix('#') else {
                // An `.mpc` value line: the value of the label before it.
                if let Some(key) = label.take() {
                    pairs.push((key, line.to_string()));
                }
                continue;
            };
            label = None;
            let body = body.trim();
            if let Some(key) = body.strip_suffix(':') {
                label = Some(key.trim().to_string());
                continue;
            }
            let (key, value) = match body.find(|c: char| c.is_whitespace() || c == ':') {
                Some(at) => (&body[..at], body[at + 1..].trim()),
                None => (body, ""),
            };
            if key.is_empty() {
                continue;
            }
            let value = value.trim_matches('"').replace('\t', " ");
            pairs.push((key.to_string(), value));
        }
        pairs
    }

    /// A measurement with no header, no `.mpc` extras and `up_phi` 0.
    pub fn new(
        format: SourceFormat,
        incidence: Incidence,
        quantity: Quantity,
        channels: Channels,
        samples: Vec<Sample>,
    ) -> Self {
        Self {
            format,
            sample_name: None,
            incidence,
            incidence_origin: IncidenceOrigin::Programmatic,
            up_phi_deg: 0.0,
            quantity,
            channels,
            samples,
            mpc_columns: Vec::new(),
            beam: None,
            header: Vec::new(),
        }
    }

    /// Number of samples.
    pub fn len(&self) -> usize {
        self.samples.len()
    }

    /// True when there are no samples.
    pub fn is_empty(&self) -> bool {
        self.samples.is_empty()
    }

    /// Unit vector towards the light source, z = front normal.
    pub fn incident_direction(&self) -> DVec3 {
        self.incidence.direction()
    }

    /// The CIE-Y value of a sample (slot 0 or slot 1, see [`Channels`]).
    pub fn luminance_of(&self, sample: &Sample) -> f64 {
        sample.values[self.channels.luminance_slot()]
    }

    /// Number of samples with a "not available" (NaN) value in a used slot.
    pub fn count_unavailable(&self) -> usize {
        self.samples
            .iter()
            .filter(|s| !s.is_available(self.channels))
            .count()
    }

    /// Number of samples with a negative value in a used slot.
    pub fn count_negative(&self) -> usize {
        let n = self.channels.count();
        self.samples
            .iter()
            .filter(|s| s.values[..n].iter().any(|&v| v < 0.0))
            .count()
    }

    /// Number of samples in a hemisphere.
    pub fn count_in(&self, hemisphere: Hemisphere) -> usize {
        self.samples
            .iter()
            .filter(|s| s.hemisphere() == hemisphere)
            .count()
    }

    /// True when `mpc_columns` is either empty or parallel to `samples`.
    pub fn mpc_columns_consistent(&self) -> bool {
        self.mpc_columns.is_empty() || self.mpc_columns.len() == self.samples.len()
    }

    /// A copy keeping only the samples at `indices` (in that order), with
    /// their `.mpc` columns. Indices out of range are ignored.
    pub fn with_samples_at(&self, indices: &[usize]) -> Measurement {
        let keep_mpc = self.mpc_columns.len() == self.samples.len();
        let mut out = self.clone_without_samples();
        out.samples.reserve(indices.len());
        for &i in indices {
            if let Some(sample) = self.samples.get(i) {
                out.samples.push(*sample);
                if keep_mpc {
                    out.mpc_columns.push(self.mpc_columns[i]);
                }
            }
        }
        out
    }

    /// A copy of every field except the samples and `.mpc` columns (empty).
    pub fn clone_without_samples(&self) -> Measurement {
        Measurement {
            format: self.format,
            sample_name: self.sample_name.clone(),
            incidence: self.incidence,
            incidence_origin: self.incidence_origin,
            up_phi_deg: self.up_phi_deg,
            quantity: self.quantity.clone(),
            channels: self.channels,
            samples: Vec::new(),
            mpc_columns: Vec::new(),
            beam: self.beam.clone(),
            header: self.header.clone(),
        }
    }
}

/// Serde helpers writing NaN ("not available") as JSON `null` and back.
mod nan_as_null {
    /// For `f64` fields.
    pub(super) mod scalar {
        use serde::{Deserialize, Deserializer, Serializer};

        pub(crate) fn serialize<S: Serializer>(v: &f64, s: S) -> Result<S::Ok, S::Error> {
            if v.is_nan() {
                s.serialize_none()
            } else {
                s.serialize_some(v)
            }
        }

        pub(crate) fn deserialize<'de, D: Deserializer<'de>>(d: D) -> Result<f64, D::Error> {
            Ok(Option::<f64>::deserialize(d)?.unwrap_or(f64::NAN))
        }
    }

    /// For `[f64; 3]` fields.
    pub(super) mod array3 {
        use serde::{Deserialize, Deserializer, Serialize, Serializer};

        pub(crate) fn serialize<S: Serializer>(v: &[f64; 3], s: S) -> Result<S::Ok, S::Error> {
            v.map(|x| (!x.is_nan()).then_some(x)).serialize(s)
        }

        pub(crate) fn deserialize<'de, D: Deserializer<'de>>(d: D) -> Result<[f64; 3], D::Error> {
            Ok(<[Option<f64>; 3]>::deserialize(d)?.map(|x| x.unwrap_or(f64::NAN)))
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn phi_normalisation_keeps_in_range_values_bitwise() {
        for phi in [0.0, 0.1, 179.99448, 359.999] {
            assert_eq!(normalize_phi_deg(phi).to_bits(), phi.to_bits());
        }
        assert_eq!(normalize_phi_deg(-90.0), 270.0);
        assert_eq!(normalize_phi_deg(360.0), 0.0);
        assert_eq!(normalize_phi_deg(-1e-20), 0.0);
        assert_eq!(normalize_phi_deg(720.5), 0.5);
        for phi in [-179.99933f64, -0.5, -359.9, -1e-300, -360.0, -123.456789] {
            let expected = phi.rem_euclid(360.0);
            let expected = if expected >= 360.0 { 0.0 } else { expected };
            assert_eq!(normalize_phi_deg(phi), expected, "{phi}");
        }
    }

    #[test]
    fn directions_follow_the_file_convention() {
        let s = Sample::luminance(90.0, 90.0, 1.0);
        assert!((s.direction() - DVec3::Y).length() < 1e-12);
        let inc = Incidence::new(30.0, 0.0);
        let m = inc.mirror_direction();
        let expect = direction_from_degrees(30.0, 180.0);
        assert!((m - expect).length() < 1e-12);
        let t = inc.straight_through_direction();
        assert!((t - direction_from_degrees(150.0, 180.0)).length() < 1e-12);
    }

    #[test]
    fn sample_is_compact() {
        assert!(std::mem::size_of::<Sample>() <= 56);
    }
}
