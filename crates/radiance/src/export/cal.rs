//! The `.cal` file of the θ_in-dependent material.
//!
//! It holds two things, both generated from the fit:
//!
//! 1. **The parameter table.** Every real argument as a function of θ_in
//!    (degrees): brtf-fit's interpolation written as explicit cubic
//!    segments ([`Pieces`]), clamped to the measured range.
//! 2. **The BSDF.** brtf-model's formulas for the fitted type and variant,
//!    in Radiance's function language, evaluated with the parameters at
//!    the θ_in of the light: `θ_in = acos |l·n|`, where `l` is the
//!    direction to the light source sample and `n` the surface normal.
//!
//! Radiance calls the entry functions with the direction to the light
//! `(lx, ly, lz)` and the source's solid angle `om`; `Dx, Dy, Dz` (the ray
//! direction), `NxP, NyP, NzP` (the normal, turned towards the viewer) and
//! `RdotP` (the view cosine) describe the current ray. Each function file
//! is read in its own context (named after the file), so the names here
//! cannot clash with another exported material's.
//!
//! Two kinds of entry point:
//!
//! * [`Entry::Brtd`] for `BRTDfunc`: per channel the whole BSDF minus the
//!   constant diffuse parts that the material's real arguments carry
//!   (those also receive indirect light), plus the mirror and
//!   straight-through coefficients of roughness-0 rows.
//! * [`Entry::Lobe`] for `plasfunc`/`metfunc`/`transfunc`: only the
//!   specular lobes, when colour, specularity and transmission do not
//!   change with θ_in and Radiance's constant arguments can carry them.

use super::num::num;
use super::pieces::{FALLBACK_STEP, Pieces};
use brtf_fit::{Interpolation, ParamTable};
use brtf_model::{MaterialKind, Shape, Variant};
use std::collections::HashMap;
use std::fmt::Write;

/// Channel function names of the `BRTDfunc` entry.
pub(crate) const CHANNEL_FUNCTIONS: [&str; 3] = ["f_red", "f_green", "f_blue"];
/// Mirror (ideal specular reflection) coefficients of roughness-0 rows.
pub(crate) const MIRROR_VARIABLES: [&str; 3] = ["m_red", "m_green", "m_blue"];
/// Straight-through (ideal specular transmission) coefficients.
pub(crate) const THROUGH_VARIABLES: [&str; 3] = ["t_red", "t_green", "t_blue"];
/// The lobe function of the `plasfunc`/`metfunc`/`transfunc` entry.
pub(crate) const LOBE_FUNCTION: &str = "f_lobe";

/// Which Radiance material calls the file.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) enum Entry {
    /// `BRTDfunc`: the functions return the BSDF minus `rd0/π` (light in
    /// front) or `td0/π` (light behind), per channel.
    Brtd {
        /// Constant diffuse reflectance in the material's arguments.
        rd0: [f64; 3],
        /// Constant diffuse transmittance in the material's arguments.
        td0: [f64; 3],
        /// Emit the roughness-0 mirror and straight-through coefficients.
        deltas: bool,
    },
    /// `plasfunc`/`metfunc`/`transfunc`: the specular lobes only.
    Lobe,
}

/// Everything the `.cal` text depends on.
#[derive(Debug, Clone)]
pub(crate) struct CalModel<'a> {
    pub kind: MaterialKind,
    /// The shape: lobes and whether the orientation angle is a parameter.
    pub shape: Shape,
    pub variant: Variant,
    /// `K` of the roughness-0 Fresnel estimate (radiance variant).
    pub fresnel_k: f64,
    /// Orientation vector of the `*2` types (function coordinates).
    pub orientation: [f64; 3],
    pub pieces: &'a Pieces,
    pub entry: Entry,
    /// A table that follows φ_in too ([`ParamTable::azimuth`]): the
    /// parameters become functions of (θ_in, φ_in).
    pub azimuth: Option<&'a ParamTable>,
}

impl CalModel<'_> {
    /// The `.cal` text. `header` lines become a leading comment.
    pub(super) fn text(&self, header: &[String]) -> String {
        let mut o = String::new();
        o += "{\n";
        for line in header {
            // Braces would end the comment early.
            let line = line.replace(['{', '}'], "");
            if line.is_empty() {
                o += "\n";
            } else {
                o += &format!("  {line}\n");
            }
        }
        o += "}\n\n";
        let Some(table) = self.azimuth else {
            self.parameters(&mut o, "p_");
            self.constants(&mut o);
            self.geometry(&mut o);
            self.model(&mut o);
            return o;
        };
        // The same model with every parameter a function of (t, f): the
        // θ_in-only functions stay, as the mean over φ_in, for lights
        // without an azimuth (orientation along the normal).
        self.parameters(&mut o, "pm_");
        self.azimuth_parameters(&mut o, table);
        self.constants(&mut o);
        let mut rest = String::new();
        self.geometry(&mut rest);
        self.model(&mut rest);
        o += &with_azimuth_argument(&rest);
        o
    }

    /// Sections 4 to 7, after the parameters, constants and geometry.
    fn model(&self, o: &mut String) {
        if self.shape.lobes > 1 {
            return self.lobe_sum_model(o);
        }
        match self.entry {
            Entry::Brtd { .. } => self.coefficients(o),
            Entry::Lobe => {}
        }
        self.lobes(o);
        match self.entry {
            Entry::Brtd { rd0, td0, deltas } => self.brtd_entry(o, rd0, td0, deltas),
            Entry::Lobe => self.lobe_entry(o),
        }
    }

    /// Section 1b: the parameters as functions of (θ_in, φ_in): each θ_in
    /// row's value at φ_in (linear between its azimuths, periodic), then
    /// brtf-fit's θ_in interpolation through those values, its slopes
    /// worked out from them (Fritsch–Carlson for PCHIP), as
    /// [`ParamTable::args_at_direction`] does.
    fn azimuth_parameters(&self, o: &mut String, table: &ParamTable) {
        let rings = table.azimuth.as_deref().expect("an azimuth table");
        let thetas = &table.theta_in;
        let n = thetas.len();
        *o += "{ ===== 1b. The fitted parameters as functions of theta_in = t and phi_in = f\n";
        *o += "  (degrees; phi_in from u towards v = N x u, N on the light's side). Each\n";
        *o += "  theta_in row: linear in phi_in between its incidences' azimuths, periodic;\n";
        let _ = writeln!(
            o,
            "  then {} over theta_in through the rows' values at phi_in. f < 0: no azimuth,\n  the phi_in-averaged pm_ functions. }}",
            match table.method {
                Interpolation::Pchip => "monotone cubic (PCHIP, Fritsch-Carlson slopes)",
                Interpolation::Linear => "linear",
            }
        );
        *o += "lin(x, x0, x1, y0, y1) : y0 + (x - x0)/(x1 - x0)*(y1 - y0);\n";
        *o +=
            "hermite(u, h, y0, y1, d0, d1) : (2*u*u*u - 3*u*u + 1)*y0 + (u*u*u - 2*u*u + u)*h*d0\n";
        *o += "\t+ (-2*u*u*u + 3*u*u)*y1 + (u*u*u - u*u)*h*d1;\n";
        *o += "harmonic(a, b, w1, w2) : if(a*b, (w1 + w2)/(w1/a + w2/b), 0);\n";
        *o +=
            "endslope(h0, h1, d0, d1) : endslope_s((( 2*h0 + h1)*d0 - h0*d1)/(h0 + h1), d0, d1);\n";
        *o += "endslope_s(s, d0, d1) : if(s*d0, if(and(-(d0*d1) + 1e-300, abs(s) - 3*abs(d0)), 3*d0, s), 0);\n";
        let names = self.shape.param_names();
        for (p, name) in names.iter().enumerate() {
            *o += "\n";
            let same = |q: usize| rings.iter().all(|r| r.args.iter().all(|a| a[q] == a[p]));
            if let Some(q) = (0..p.min(3)).find(|&q| p < 3 && same(q)) {
                let _ = writeln!(o, "p_{name}(t, f) : p_{}(t, f);", names[q]);
                continue;
            }
            let _ = writeln!(
                o,
                "p_{name}(t, f) : if(f + .5, pa_{name}(t_clamp(t), f), pm_{name}(t));"
            );
            // Each row's value at f.
            for (r, ring) in rings.iter().enumerate() {
                let phis = &ring.phi_in;
                let values: Vec<f64> = ring.args.iter().map(|a| a[p]).collect();
                let m = phis.len();
                let body = if m == 1 {
                    num(values[0])
                } else {
                    let wrap = |x: &str| {
                        format!(
                            "lin({x}, {}, {}, {}, {})",
                            num(phis[m - 1] - 360.0),
                            num(phis[0]),
                            num(values[m - 1]),
                            num(values[0])
                        )
                    };
                    let mut chain = wrap("f - 360");
                    for k in (0..m - 1).rev() {
                        chain = format!(
                            "if(f - {}, {chain}, lin(f, {}, {}, {}, {}))",
                            num(phis[k + 1]),
                            num(phis[k]),
                            num(phis[k + 1]),
                            num(values[k]),
                            num(values[k + 1])
                        );
                    }
                    format!("if({} - f, {}, {chain})", num(phis[0]), wrap("f"))
                };
                let _ = writeln!(o, "y_{name}_{r}(f) : {body};");
            }
            // Secants, slopes and the segments.
            for i in 0..n - 1 {
                let _ = writeln!(
                    o,
                    "s_{name}_{i}(f) : (y_{name}_{}(f) - y_{name}_{i}(f))/{};",
                    i + 1,
                    num(thetas[i + 1] - thetas[i])
                );
            }
            let h = |i: usize| num(thetas[i + 1] - thetas[i]);
            if table.method == Interpolation::Pchip {
                for i in 0..n {
                    let slope = if n == 2 {
                        format!("s_{name}_0(f)")
                    } else if i == 0 {
                        format!("endslope({}, {}, s_{name}_0(f), s_{name}_1(f))", h(0), h(1))
                    } else if i == n - 1 {
                        format!(
                            "endslope({}, {}, s_{name}_{}(f), s_{name}_{}(f))",
                            h(n - 2),
                            h(n - 3),
                            n - 2,
                            n - 3
                        )
                    } else {
                        let (h0, h1) = (thetas[i] - thetas[i - 1], thetas[i + 1] - thetas[i]);
                        format!(
                            "harmonic(s_{name}_{}(f), s_{name}_{i}(f), {}, {})",
                            i - 1,
                            num(2.0 * h1 + h0),
                            num(h1 + 2.0 * h0)
                        )
                    };
                    let _ = writeln!(o, "d_{name}_{i}(f) : {slope};");
                }
            }
            let segment = |i: usize| match table.method {
                Interpolation::Pchip => format!(
                    "hermite((t - {})/{}, {}, y_{name}_{i}(f), y_{name}_{}(f), d_{name}_{i}(f), d_{name}_{}(f))",
                    num(thetas[i]),
                    h(i),
                    h(i),
                    i + 1,
                    i + 1
                ),
                Interpolation::Linear => format!(
                    "lin(t, {}, {}, y_{name}_{i}(f), y_{name}_{}(f))",
                    num(thetas[i]),
                    num(thetas[i + 1]),
                    i + 1
                ),
            };
            let mut chain = segment(n - 2);
            for i in (0..n - 2).rev() {
                chain = format!("if(t - {}, {chain}, {})", num(thetas[i + 1]), segment(i));
            }
            let _ = writeln!(o, "pa_{name}(t, f) : {chain};");
        }
        *o += "\n";
    }

    fn iso(&self) -> bool {
        !self.kind.is_anisotropic()
    }

    fn transmitting(&self) -> bool {
        self.kind.is_transmitting()
    }

    /// Section 1: the parameter functions `<prefix><name>(t)`.
    fn parameters(&self, o: &mut String, prefix: &str) {
        let nodes = &self.pieces.nodes;
        let (lo, hi) = (nodes[0], nodes[nodes.len() - 1]);
        let list: Vec<String> = nodes.iter().map(|&x| num(x)).collect();
        *o += "{ ===== 1. The fitted parameters as functions of theta_in (degrees) =====\n";
        if self.pieces.exact {
            *o += &format!("  Measured incidences: {}.\n", list.join(" "));
            *o += "  Each segment is a cubic in s = theta_in - (segment start), exactly\n";
            *o += "  brtf-fit's interpolation; outside the measured range the end values hold. }\n";
        } else {
            let _ = writeln!(
                o,
                "  brtf-fit's interpolation sampled every {} deg from {} to {}, straight",
                num(FALLBACK_STEP),
                num(lo),
                num(hi)
            );
            *o += "  lines in between; outside the measured range the end values hold. }\n";
        }
        let _ = writeln!(o, "t_lo : {};", num(lo));
        let _ = writeln!(o, "t_hi : {};", num(hi));
        *o += "t_clamp(t) : if(t - t_hi, t_hi, if(t_lo - t, t_lo, t));\n";
        *o += "cubic(s, a0, a1, a2, a3) : a0 + s*(a1 + s*(a2 + s*a3));\n";
        let names = self.shape.param_names();
        for (p, name) in names.iter().enumerate() {
            let segs = &self.pieces.segments[p];
            *o += "\n";
            // A grey colour: green and blue repeat red.
            let same_colour = (0..p.min(3)).find(|&q| self.pieces.segments[q] == *segs);
            if let (true, Some(q)) = (p < 3, same_colour) {
                let _ = writeln!(o, "{prefix}{name}(t) : {prefix}{}(t);", names[q]);
                continue;
            }
            let _ = writeln!(o, "{prefix}{name}(t) : {prefix}{name}_0(t_clamp(t));");
            let last = segs.len() - 1;
            for (i, seg) in segs.iter().enumerate() {
                let c = seg.coef;
                let cubic = format!(
                    "cubic(t - {}, {}, {}, {}, {})",
                    num(seg.start),
                    num(c[0]),
                    num(c[1]),
                    num(c[2]),
                    num(c[3])
                );
                if i < last {
                    let _ = writeln!(
                        o,
                        "{prefix}{name}_{i}(t) : if(t - {}, {prefix}{name}_{}(t), {cubic});",
                        num(nodes[i + 1]),
                        i + 1
                    );
                } else {
                    let _ = writeln!(o, "{prefix}{name}_{i}(t) : {cubic};");
                }
            }
        }
        *o += "\n";
    }

    /// Section 2: constants and helpers.
    fn constants(&self, o: &mut String) {
        *o += "{ ===== 2. Constants and helpers ===== }\n";
        *o += "ftiny : 1e-6;                            { rtrace's FTINY }\n";
        *o += "cutoff(x) : if(x - ftiny, x, 0);         { rtrace drops lobe values <= 1e-6 }\n";
        *o += "ex(x) : if(x - 600, 0, exp(-x));          { exp(-x) without underflow }\n";
        if self.variant == Variant::Radiance && self.iso() {
            let _ = writeln!(
                o,
                "fresnel_k : {};\nfres(c) : exp(-5.85*c) - fresnel_k;     {{ roughness-0 Fresnel estimate }}",
                num(self.fresnel_k)
            );
        }
        *o += "\n";
    }

    /// Section 3: the current ray and, for the `*2` types, the tangent frame.
    fn geometry(&self, o: &mut String) {
        *o += "{ ===== 3. Geometry: the current ray and the light =====\n";
        *o += "  NxP NyP NzP is the normal turned towards the viewer, RdotP the view cosine. }\n";
        *o += "cosv = max(RdotP, .001);                 { view cosine, clamped as rtrace does }\n";
        *o += "vx = -Dx; vy = -Dy; vz = -Dz;            { towards the viewer }\n";
        *o +=
            "cosl(lx, ly, lz) = lx*NxP + ly*NyP + lz*NzP;   { light cosine, < 0: light behind }\n";
        *o += "thin(c) : acos(min(1, abs(c)))/DEGREE;   { theta_in of the light, degrees }\n";
        if self.variant == Variant::Ward1992 {
            *o += "e6 = exp(-6*cosv);                       { Ward 1992 Fresnel estimate }\n";
        }
        if !self.iso() {
            *o +=
                "{ Tangent frame: v_hat = normalize(N x u0), u_hat = v_hat x N; the u roughness\n";
            *o += "  applies along u_hat. u0 parallel to N: mean roughness on both axes. }\n";
            if self.shape.oriented {
                *o +=
                    "{ u0 turns in the surface plane by the fitted angle orient, degrees from +x\n";
                *o += "  towards +y, which follows theta_in = t like every parameter. }\n";
                *o += "u0x(t) = cos(p_orient(t)*DEGREE); u0y(t) = sin(p_orient(t)*DEGREE); u0z(t) = 0;\n";
                *o += "crx(t) = NyP*u0z(t) - NzP*u0y(t); cry(t) = NzP*u0x(t) - NxP*u0z(t);\n";
                *o += "crz(t) = NxP*u0y(t) - NyP*u0x(t);\n";
                *o += "crl(t) = sqrt(crx(t)*crx(t) + cry(t)*cry(t) + crz(t)*crz(t));\n";
                *o += "vhx(t) = if(crl(t), crx(t)/crl(t), 0); vhy(t) = if(crl(t), cry(t)/crl(t), 0);\n";
                *o += "vhz(t) = if(crl(t), crz(t)/crl(t), 0);\n";
                *o += "uhx(t) = vhy(t)*NzP - vhz(t)*NyP; uhy(t) = vhz(t)*NxP - vhx(t)*NzP;\n";
                *o += "uhz(t) = vhx(t)*NyP - vhy(t)*NxP;\n";
            } else {
                let [x, y, z] = self.orientation;
                let _ = writeln!(o, "u0x : {}; u0y : {}; u0z : {};", num(x), num(y), num(z));
                *o +=
                    "crx = NyP*u0z - NzP*u0y; cry = NzP*u0x - NxP*u0z; crz = NxP*u0y - NyP*u0x;\n";
                *o += "crl = sqrt(crx*crx + cry*cry + crz*crz);\n";
                *o += "vhx = if(crl, crx/crl, 0); vhy = if(crl, cry/crl, 0); vhz = if(crl, crz/crl, 0);\n";
                *o +=
                    "uhx = vhy*NzP - vhz*NyP; uhy = vhz*NxP - vhx*NzP; uhz = vhx*NyP - vhy*NxP;\n";
            }
            if self.shape.lobes == 1 {
                self.roughness_squares(o);
            }
        }
        *o += "\n";
    }

    /// A frame quantity of section 3: a variable, or a function of `t`
    /// when the orientation follows θ_in.
    fn frame(&self, name: &str) -> String {
        if self.shape.oriented {
            format!("{name}(t)")
        } else {
            name.to_string()
        }
    }

    /// `w2u(t)`, `w2v(t)`: the squared roughnesses along u_hat and v_hat.
    fn roughness_squares(&self, o: &mut String) {
        let crl = self.frame("crl");
        let _ = writeln!(
            o,
            "w2u(t) = if({crl}, sq(p_rough_u(t)), (sq(p_rough_u(t)) + sq(p_rough_v(t)))/2);"
        );
        let _ = writeln!(
            o,
            "w2v(t) = if({crl}, sq(p_rough_v(t)), (sq(p_rough_u(t)) + sq(p_rough_v(t)))/2);"
        );
    }

    /// Section 4: the split into specular, diffuse and transmitted parts
    /// at `t` = θ_in (they depend on the view through the Fresnel terms).
    fn coefficients(&self, o: &mut String) {
        let radiance = self.variant == Variant::Radiance;
        let ward = self.variant == Variant::Ward1992;
        let metal = self.kind.is_metal();
        if self.shape.lobes == 1 {
            *o += "{ ===== 4. Specular, diffuse and transmitted fractions at theta_in = t =====\n";
            *o +=
                "  The colour is modified by a pattern on the material, if any (CrP CgP CbP). }\n";
        }
        *o += "col(k, t) = select(k, p_red(t)*CrP, p_green(t)*CgP, p_blue(t)*CbP);\n";
        if self.iso() {
            *o += "pure(t) : if(sq(p_rough(t)) - ftiny, -1, 1);   { roughness <= 0.001: mirror-like }\n";
        }
        let fresnel = radiance && self.iso();
        if fresnel {
            *o += "fresnel(t) : if(pure(t), if(.017999 - p_spec(t), -1, 1), -1);\n";
            *o += "spec(t) = if(fresnel(t), p_spec(t) + fres(cosv)*(1 - p_spec(t)), p_spec(t));\n";
        } else if ward && !metal {
            *o += "spec(t) = p_spec(t) + e6*(1 - p_spec(t));\n";
        } else {
            *o += "spec(t) = p_spec(t);\n";
        }
        if ward && metal {
            *o += "wspec(k, t) = col(k, t)*p_spec(t) + (1 - col(k, t)*p_spec(t))*e6;\n";
        }
        if self.transmitting() {
            *o += "trn(t) = p_trans(t)*(1 - spec(t));\n";
            *o += "tsp(t) = trn(t)*p_tspec(t);\n";
            *o += "tdf(t) = trn(t) - tsp(t);\n";
            *o += "rdf(t) = 1 - trn(t) - spec(t);\n";
        } else {
            *o += "rdf(t) = 1 - spec(t);\n";
        }
        if fresnel {
            let diffuse_on = if self.transmitting() {
                "or(rdf(t) - ftiny, tdf(t) - ftiny)"
            } else {
                "rdf(t) - ftiny"
            };
            let _ = writeln!(
                o,
                "lfres(c, t) = if(and(fresnel(t), {diffuse_on}), 1 - fres(c), 1);"
            );
        }
        *o += "\n";
    }

    /// Section 5: the reflected (and transmitted) specular lobes.
    fn lobes(&self, o: &mut String) {
        let widen = "om/(4*PI)";
        if self.shape.lobes == 1 {
            *o += "{ ===== 5. Specular lobes (no specularity or colour); c = |light cosine|,\n";
            *o += "  h = l + v (not normalised), om = source solid angle. The reflected lobe is\n";
            *o += "  widened by om/(4 pi) as rtrace does on flat surfaces. }\n";
        }
        let [ux, uy, uz, vx, vy, vz] =
            ["uhx", "uhy", "uhz", "vhx", "vhy", "vhz"].map(|n| self.frame(n));
        if self.iso() {
            let _ = writeln!(
                o,
                "lobe(c, hx, hy, hz, om, t) = lobe_h(c, hx*hx + hy*hy + hz*hz, hx*NxP + hy*NyP + hz*NzP, sq(p_rough(t)) + {widen});"
            );
            *o += match self.variant {
                Variant::Radiance => {
                    "lobe_h(c, hh, hn, w) = cutoff(ex((hh/(hn*hn) - 1)/w)*hh/(PI*w*sq(hn*hn)));\n"
                }
                Variant::Manual2004 => {
                    "lobe_h(c, hh, hn, w) = ex((hh/(hn*hn) - 1)/w)/(4*PI*w*c*cosv);\n"
                }
                Variant::Ward1992 => {
                    "lobe_h(c, hh, hn, w) = ex((2 - 2*hn/sqrt(hh))/w)/(4*PI*w*sqrt(c*cosv));\n"
                }
            };
        } else {
            let _ = writeln!(
                o,
                "lobe(c, hx, hy, hz, om, t) = lobe_h(c, hx*hx + hy*hy + hz*hz, hx*NxP + hy*NyP + hz*NzP,\n\
                 \thx*{ux} + hy*{uy} + hz*{uz}, hx*{vx} + hy*{vy} + hz*{vz}, w2u(t) + {widen}, w2v(t) + {widen});"
            );
            *o += match self.variant {
                Variant::Radiance => {
                    "lobe_h(c, hh, hn, hu, hv, wu, wv) = cutoff(ex((hu*hu/wu + hv*hv/wv)/(hn*hn))*hh/(PI*sq(hn*hn)*sqrt(wu*wv)));\n"
                }
                Variant::Manual2004 => {
                    "lobe_h(c, hh, hn, hu, hv, wu, wv) = ex((hu*hu/wu + hv*hv/wv)/(hn*hn))/(4*PI*sqrt(wu*wv)*c*cosv);\n"
                }
                Variant::Ward1992 => {
                    "lobe_h(c, hh, hn, hu, hv, wu, wv) = ex(2*(hu*hu/wu + hv*hv/wv)/(hh*(1 + hn/sqrt(hh))))/(4*PI*sqrt(wu*wv)*sqrt(c*cosv));\n"
                }
            };
        }
        if self.transmitting() {
            let geometry = match self.variant {
                Variant::Manual2004 => "(c*cosv)",
                _ => "sqrt(c*cosv)",
            };
            *o += "{ Transmitted lobe around the straight-through direction, widened by om/pi. }\n";
            if self.iso() {
                *o += "tlobe(c, hx, hy, hz, om, t) = tlobe_h(c, hx*hx + hy*hy + hz*hz, sq(p_rough(t)) + om/PI);\n";
                let g = if self.variant == Variant::Radiance {
                    "cutoff(ex(x/b)/(PI*b))"
                } else {
                    "ex(x/b)/(PI*b)"
                };
                let _ = writeln!(o, "tlobe_h(c, x, b) = {g}/{geometry};");
            } else {
                let _ = writeln!(
                    o,
                    "tlobe(c, hx, hy, hz, om, t) = tlobe_h(c, hx*hx + hy*hy + hz*hz, hx*NxP + hy*NyP + hz*NzP,\n\
                     \thx*{ux} + hy*{uy} + hz*{uz}, hx*{vx} + hy*{vy} + hz*{vz}, w2u(t) + om/PI, w2v(t) + om/PI);"
                );
                *o += "tlobe_h(c, hh, hn, hu, hv, bu, bv) = tlobe_e(c, ex(tl_x(tl_s2(hh, hn), hu, hv, bu, bv)), bu, bv);\n";
                *o += "tl_s2(hh, hn) = if(hh - 1e-12, 1 - hn*hn/hh, hh);\n";
                *o += "tl_x(s2, hu, hv, bu, bv) = if(s2 - 1e-12, (hu*hu/bu + hv*hv/bv)/s2, 0);\n";
                if self.variant == Variant::Radiance {
                    let _ = writeln!(
                        o,
                        "tlobe_e(c, e, bu, bv) = if(e*sqrt(c/(cosv*bu*bv))/PI - ftiny, e/(PI*sqrt(bu*bv)*{geometry}), 0);"
                    );
                } else {
                    let _ = writeln!(o, "tlobe_e(c, e, bu, bv) = e/(PI*sqrt(bu*bv)*{geometry});");
                }
            }
        }
        *o += "\n";
    }

    /// Section 6 for `BRTDfunc`: the whole BSDF per channel.
    fn brtd_entry(&self, o: &mut String, rd0: [f64; 3], td0: [f64; 3], deltas: bool) {
        *o +=
            "{ ===== 6. The BSDF f(l, v) in 1/sr for channel k (1 red, 2 green, 3 blue) ===== }\n";
        self.brtd_head(o);
        self.brtd_lobe(o);
        self.brtd_channels(o, rd0, td0);
        if deltas {
            self.delta_head(o);
            self.mirror_function(o);
            self.delta_variables(o);
        }
    }

    /// `bsdf` and `bsdf_c`: the light's cosine, half vector and θ_in.
    fn brtd_head(&self, o: &mut String) {
        *o += "bsdf(k, lx, ly, lz, om) = bsdf_c(k, cosl(lx, ly, lz), lx + vx, ly + vy, lz + vz, om);\n";
        if self.transmitting() {
            *o += "bsdf_c(k, c, hx, hy, hz, om) = if(c, refl(k, c, hx, hy, hz, om, thin(c)),\n\
                   \tif(-c, trans(k, -c, hx, hy, hz, om, thin(c)), 0));\n";
        } else {
            *o += "bsdf_c(k, c, hx, hy, hz, om) = if(c, refl(k, c, hx, hy, hz, om, thin(c)), 0);\n";
        }
    }

    /// `refl` (and `trans`) of one primitive at θ_in = t.
    fn brtd_lobe(&self, o: &mut String) {
        let ward_metal = self.variant == Variant::Ward1992 && self.kind.is_metal();
        let lfres = if self.variant == Variant::Radiance && self.iso() {
            "*lfres(c, t)"
        } else {
            ""
        };
        let not_pure = |cond: &str| {
            if self.iso() {
                format!("and(-pure(t), {cond})")
            } else {
                cond.to_string()
            }
        };
        if self.transmitting() {
            *o += "refl(k, c, hx, hy, hz, om, t) = if(trn(t) - (1 - ftiny), 0,\n\
                   \trdiff(k, c, t) + rspec(k, c, hx, hy, hz, om, t));\n";
        } else {
            *o += "refl(k, c, hx, hy, hz, om, t) = rdiff(k, c, t) + rspec(k, c, hx, hy, hz, om, t);\n";
        }
        if ward_metal {
            *o += "rdiff(k, c, t) = col(k, t)*(1 - wspec(k, t))/PI;\n";
        } else {
            let _ = writeln!(
                o,
                "rdiff(k, c, t) = if(rdf(t) - ftiny, col(k, t)*rdf(t){lfres}/PI, 0);"
            );
        }
        let (on, colour) = if ward_metal {
            ("p_spec(t) - ftiny", "wspec(k, t)")
        } else if self.kind.is_metal() {
            ("spec(t) - ftiny", "col(k, t)*p_spec(t)")
        } else {
            ("spec(t) - ftiny", "spec(t)")
        };
        let _ = writeln!(
            o,
            "rspec(k, c, hx, hy, hz, om, t) = if({}, {colour}*lobe(c, hx, hy, hz, om, t), 0);",
            not_pure(on)
        );
        if self.transmitting() {
            *o += "trans(k, c, hx, hy, hz, om, t) = if(trn(t) - ftiny,\n\
                   \ttdiff(k, c, t) + tspec(k, c, hx, hy, hz, om, t), 0);\n";
            let _ = writeln!(
                o,
                "tdiff(k, c, t) = if(tdf(t) - ftiny, col(k, t)*tdf(t){lfres}/PI, 0);"
            );
            let _ = writeln!(
                o,
                "tspec(k, c, hx, hy, hz, om, t) = if({}, col(k, t)*tsp(t)*tlobe(c, hx, hy, hz, om, t), 0);",
                not_pure("tsp(t) - ftiny")
            );
        }
    }

    /// Section 7: the constant diffuse parts and the channel functions.
    fn brtd_channels(&self, o: &mut String, rd0: [f64; 3], td0: [f64; 3]) {
        *o += "\n{ ===== 7. What BRTDfunc calls =====\n";
        *o += "  The material's real arguments hold constant diffuse parts (the smallest over\n";
        *o += "  theta_in, so they also serve indirect light; Radiance applies a pattern to\n";
        *o += "  them); the functions add the rest. }\n";
        let channel = ["red", "green", "blue"];
        for (k, name) in channel.iter().enumerate() {
            let _ = writeln!(
                o,
                "rd0_{name} : {}; td0_{name} : {};",
                num(rd0[k]),
                num(td0[k])
            );
        }
        for (k, name) in channel.iter().enumerate() {
            let _ = writeln!(
                o,
                "{}(lx, ly, lz, om) = bsdf({}, lx, ly, lz, om) - {}*if(cosl(lx, ly, lz), rd0_{name}, td0_{name})/PI;",
                CHANNEL_FUNCTIONS[k],
                k + 1,
                ["CrP", "CgP", "CbP"][k]
            );
        }
    }

    /// The roughness-0 comment and the view's θ.
    fn delta_head(&self, o: &mut String) {
        *o += "\n{ Roughness 0: mirror and straight-through coefficients, at the view's theta. }\n";
        *o += "tview = acos(min(1, RdotP))/DEGREE;\n";
    }

    /// `mirror(k, t)` of one primitive.
    fn mirror_function(&self, o: &mut String) {
        let mirror = if self.kind.is_metal() {
            if self.variant == Variant::Radiance {
                "if(and(fresnel(t), fres(cosv) - ftiny), fres(cosv) + col(k, t)*p_spec(t)*(1 - fres(cosv)), col(k, t)*p_spec(t))"
            } else {
                "col(k, t)*p_spec(t)"
            }
        } else {
            "spec(t)"
        };
        let _ = writeln!(o, "mirror(k, t) = if(pure(t), {mirror}, 0);");
    }

    /// The variables BRTDfunc reads for the mirror and straight-through rays.
    fn delta_variables(&self, o: &mut String) {
        for (k, var) in MIRROR_VARIABLES.iter().enumerate() {
            let _ = writeln!(o, "{var} = mirror({}, tview);", k + 1);
        }
        if self.transmitting() {
            *o += "through(k, t) = if(pure(t), col(k, t)*tsp(t), 0);\n";
            for (k, var) in THROUGH_VARIABLES.iter().enumerate() {
                let _ = writeln!(o, "{var} = through({}, tview);", k + 1);
            }
        }
    }

    /// Sections 4 to 7 of a lobe sum: the weights, each lobe's functions
    /// (those of one primitive with its roughness, named `…_j`), and the
    /// entry functions summing the lobes with their weights at θ_in = t.
    fn lobe_sum_model(&self, o: &mut String) {
        let n = self.shape.lobes;
        let aniso = !self.iso();
        *o += "{ ===== 4. The lobes' weights at theta_in = t: stick-breaking splits, as the\n";
        *o += "  static material's mixfunc tree mix(lobe 1, mix(lobe 2, ...), split1). }\n";
        for j in 0..n {
            let _ = writeln!(o, "w_lobe{}(t) = {};", j + 1, weight_expression(j, n));
        }
        *o += "\n";
        let brtd = matches!(self.entry, Entry::Brtd { .. });
        let deltas = matches!(self.entry, Entry::Brtd { deltas: true, .. });
        for j in 1..=n {
            let roughness = if aniso {
                format!("rough_u{j} and rough_v{j}")
            } else {
                format!("rough{j}")
            };
            let _ = writeln!(
                o,
                "{{ ===== 5.{j} Lobe {j} of {n}: one {} with roughness {roughness}, its\n  \
                 functions named ..._{j}. The colour is modified by a pattern, if any (CrP CgP\n  \
                 CbP). Lobes are not normalised: c = |light cosine|, h = l + v, om = source\n  \
                 solid angle, the lobe widened by om/(4 pi) as on flat surfaces. }}",
                self.kind
            );
            let mut lobe = String::new();
            if aniso {
                self.roughness_squares(&mut lobe);
            }
            if brtd {
                self.coefficients(&mut lobe);
            }
            self.lobes(&mut lobe);
            if brtd {
                self.brtd_lobe(&mut lobe);
            }
            if deltas {
                self.mirror_function(&mut lobe);
            }
            *o += &rename_for_lobe(&lobe, j);
            *o += "\n";
        }
        let sum = |call: &str| {
            (1..=n)
                .map(|j| format!("w_lobe{j}(t)*{}", call.replacen('(', &format!("_{j}("), 1)))
                .collect::<Vec<_>>()
                .join("\n\t+ ")
        };
        match self.entry {
            Entry::Brtd { rd0, td0, deltas } => {
                *o +=
                    "{ ===== 6. The BSDF f(l, v) in 1/sr for channel k (1 red, 2 green, 3 blue):\n";
                *o += "  the lobes' BSDFs weighted. }\n";
                self.brtd_head(o);
                let _ = writeln!(
                    o,
                    "refl(k, c, hx, hy, hz, om, t) = {};",
                    sum("refl(k, c, hx, hy, hz, om, t)")
                );
                self.brtd_channels(o, rd0, td0);
                if deltas {
                    self.delta_head(o);
                    let _ = writeln!(o, "mirror(k, t) = {};", sum("mirror(k, t)"));
                    self.delta_variables(o);
                }
            }
            Entry::Lobe => {
                *o += "{ ===== 6. What the material calls: the lobes at the light's theta_in,\n";
                *o += "  weighted. Radiance scales them by the constant specularity (and colour, for\n";
                *o += "  metals) and adds the constant diffuse part itself. }\n";
                let _ = writeln!(
                    o,
                    "{LOBE_FUNCTION}(lx, ly, lz, om) = lobe_c(cosl(lx, ly, lz), lx + vx, ly + vy, lz + vz, om);"
                );
                *o += "lobe_c(c, hx, hy, hz, om) = if(c, lobe(c, hx, hy, hz, om, thin(c)), 0);\n";
                let _ = writeln!(
                    o,
                    "lobe(c, hx, hy, hz, om, t) = {};",
                    sum("lobe(c, hx, hy, hz, om, t)")
                );
            }
        }
    }

    /// Section 6 for `plasfunc`/`metfunc`/`transfunc`: the lobes alone;
    /// Radiance multiplies them by the constant specular fractions.
    fn lobe_entry(&self, o: &mut String) {
        *o += "{ ===== 6. What the material calls: the specular lobe at the light's theta_in.\n";
        *o +=
            "  Radiance scales it by the constant specularity (and colour, for metals) and adds\n";
        *o += "  the constant diffuse parts itself. }\n";
        let _ = writeln!(
            o,
            "{LOBE_FUNCTION}(lx, ly, lz, om) = lobe_c(cosl(lx, ly, lz), lx + vx, ly + vy, lz + vz, om);"
        );
        if self.transmitting() {
            *o += "lobe_c(c, hx, hy, hz, om) = if(c, lobe(c, hx, hy, hz, om, thin(c)),\n\
                   \tif(-c, tlobe(-c, hx, hy, hz, om, thin(c)), 0));\n";
        } else {
            *o += "lobe_c(c, hx, hy, hz, om) = if(c, lobe(c, hx, hy, hz, om, thin(c)), 0);\n";
        }
    }
}

/// The weight of lobe `j` (0-based) of `n` at θ_in = t, from the splits
/// by stick-breaking: `s1`, `(1 - s1) s2`, …, `Π (1 - s_k)`.
fn weight_expression(j: usize, n: usize) -> String {
    let mut factors: Vec<String> = (1..=j.min(n - 1))
        .map(|k| format!("(1 - p_split{k}(t))"))
        .collect();
    if j < n - 1 {
        factors.push(format!("p_split{}(t)", j + 1));
    }
    factors.join("*")
}

/// One primitive's functions made lobe `j`'s: every name the text
/// defines gets the suffix `_j`, and the roughness parameters become lobe
/// `j`'s (`p_rough` → `p_rough{j}`, `p_rough_u` → `p_rough_u{j}`, …).
/// Comments are left as they are.
fn rename_for_lobe(text: &str, j: usize) -> String {
    let mut map: HashMap<String, String> = defined_names(text)
        .into_iter()
        .map(|name| {
            let renamed = format!("{name}_{j}");
            (name, renamed)
        })
        .collect();
    for base in ["p_rough", "p_rough_u", "p_rough_v"] {
        map.insert(base.to_string(), format!("{base}{j}"));
    }
    rename_identifiers(text, &map)
}

/// The text without its `{ … }` comments.
fn without_comments(text: &str) -> String {
    let mut out = String::with_capacity(text.len());
    let mut depth = 0usize;
    for ch in text.chars() {
        match ch {
            '{' => depth += 1,
            '}' => depth = depth.saturating_sub(1),
            _ if depth == 0 => out.push(ch),
            _ => {}
        }
    }
    out
}

/// The names a function-file text defines: each statement's leading
/// identifier when an argument list (or nothing) and then `=` or `:`
/// follow it.
fn defined_names(text: &str) -> Vec<String> {
    let mut names = Vec::new();
    for statement in without_comments(text).split(';') {
        let s = statement.trim_start();
        let end = s
            .find(|c: char| !(c.is_ascii_alphanumeric() || c == '_'))
            .unwrap_or(s.len());
        if end == 0 || !s.starts_with(|c: char| c.is_ascii_alphabetic() || c == '_') {
            continue;
        }
        let mut rest = s[end..].trim_start();
        if rest.starts_with('(') {
            let mut depth = 0usize;
            let mut close = None;
            for (i, c) in rest.char_indices() {
                match c {
                    '(' => depth += 1,
                    ')' => {
                        depth -= 1;
                        if depth == 0 {
                            close = Some(i);
                            break;
                        }
                    }
                    _ => {}
                }
            }
            let Some(close) = close else { continue };
            rest = rest[close + 1..].trim_start();
        }
        if rest.starts_with(['=', ':']) {
            let name = s[..end].to_string();
            if !names.contains(&name) {
                names.push(name);
            }
        }
    }
    names
}

/// `text` with every identifier in `map` replaced, outside comments;
/// numbers (`1e-6`, `.5`) are kept whole.
fn rename_identifiers(text: &str, map: &HashMap<String, String>) -> String {
    let mut out = String::with_capacity(text.len() + text.len() / 8);
    let chars: Vec<char> = text.chars().collect();
    let mut i = 0;
    let mut depth = 0usize;
    while i < chars.len() {
        let c = chars[i];
        if c == '{' || (depth > 0 && c != '}') {
            depth += usize::from(c == '{');
            out.push(c);
            i += 1;
        } else if c == '}' {
            depth = depth.saturating_sub(1);
            out.push(c);
            i += 1;
        } else if c.is_ascii_digit() || c == '.' {
            // A number: digits, a point, an exponent with its sign.
            let start = i;
            i += 1;
            while i < chars.len() {
                let d = chars[i];
                if d.is_ascii_digit() || d == '.' {
                    i += 1;
                } else if matches!(d, 'e' | 'E') {
                    i += 1;
                    if i < chars.len() && matches!(chars[i], '+' | '-') {
                        i += 1;
                    }
                } else {
                    break;
                }
            }
            out.extend(&chars[start..i]);
        } else if c.is_ascii_alphabetic() || c == '_' {
            let start = i;
            while i < chars.len() && (chars[i].is_ascii_alphanumeric() || chars[i] == '_') {
                i += 1;
            }
            let word: String = chars[start..i].iter().collect();
            out += map.get(&word).unwrap_or(&word);
        } else {
            out.push(c);
            i += 1;
        }
    }
    out
}

/// Sections 3 to 7 of a (θ_in, φ_in) table: every function of θ_in `t`
/// also takes φ_in `f`, and the entry points work φ_in out from the light
/// as they work out θ_in. The generated text passes `t` always as the
/// last argument, `(t)` or `, t)`, so that is what is rewritten.
fn with_azimuth_argument(text: &str) -> String {
    let text = text
        .replace("(t)", "(t, f)")
        .replace(", t)", ", t, f)")
        .replace(", thin(c))", ", thin(c), f)")
        .replace("(k, c, hx, hy, hz, om) = ", "(k, c, hx, hy, hz, om, f) = ")
        .replace("(c, hx, hy, hz, om) = ", "(c, hx, hy, hz, om, f) = ")
        .replace("lz + vz, om);", "lz + vz, om, phin(lx, ly, lz));");
    let azimuth = "{ The light's azimuth phi_in (degrees) from u towards v = N x u, with N the\n  \
        normal on the light's side; -1 where the orientation is along the normal. }\n\
        phin(lx, ly, lz) = if(crl, azim(if(cosl(lx, ly, lz), 1, -1)*(lx*vhx + ly*vhy + lz*vhz),\n\
        \tlx*uhx + ly*uhy + lz*uhz), -1);\n\
        azim(y, x) : turn(atan2(y, x)/DEGREE);\n\
        turn(a) : a - 360*floor(a/360);\n\n";
    // After the geometry section, which defines the tangent frame.
    match text.find("{ ===== 4.").or_else(|| text.find("{ ===== 5.")) {
        Some(at) => format!("{}{azimuth}{}", &text[..at], &text[at..]),
        None => format!("{azimuth}{text}"),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_lobe_s_names_get_its_suffix_and_nothing_else_does() {
        let text = "{ lobe(c) and p_rough stay in comments }\n\
                    pure(t) : if(sq(p_rough(t)) - 1e-6, -1, 1);\n\
                    lobe(c, t) = lobe_h(c, sq(p_rough_u(t)) + om/(4*PI))\n\
                    \t+ if(pure(t), 2.5e-3, .5);\n\
                    lobe_h(c, w) = exp(-c/w); e6 = exp(-6*cosv);\n";
        assert_eq!(defined_names(text), ["pure", "lobe", "lobe_h", "e6"]);
        let renamed = rename_for_lobe(text, 2);
        assert_eq!(
            renamed,
            "{ lobe(c) and p_rough stay in comments }\n\
             pure_2(t) : if(sq(p_rough2(t)) - 1e-6, -1, 1);\n\
             lobe_2(c, t) = lobe_h_2(c, sq(p_rough_u2(t)) + om/(4*PI))\n\
             \t+ if(pure_2(t), 2.5e-3, .5);\n\
             lobe_h_2(c, w) = exp(-c/w); e6_2 = exp(-6*cosv);\n"
        );
    }

    #[test]
    fn weights_break_the_stick() {
        assert_eq!(weight_expression(0, 2), "p_split1(t)");
        assert_eq!(weight_expression(1, 2), "(1 - p_split1(t))");
        assert_eq!(weight_expression(1, 3), "(1 - p_split1(t))*p_split2(t)");
        assert_eq!(
            weight_expression(2, 3),
            "(1 - p_split1(t))*(1 - p_split2(t))"
        );
    }
}
