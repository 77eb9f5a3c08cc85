//! `EnergyRule::Exact`: each incidence's model carries the data's energy
//! (Σ ΔΩ |cos θ_out| m = Σ ΔΩ |cos θ_out| y over the fitted samples), and a
//! model that describes the data is fitted exactly as without the rows.

use super::{material, synth};
use crate::config::{EnergyRule, FitConfig};
use crate::data::IncidenceData;
use crate::fitter::{fit_global, fit_incidence};
use crate::report::FitReport;
use brtf_model::{Bsdf, EvalOptions, Material, MaterialKind, direction};

/// The model's and the data's energy over `data`'s samples, channel 0.
fn energies(data: &IncidenceData, report: &FitReport, kind: MaterialKind) -> (f64, f64) {
    let bsdf = Bsdf::new(
        &material(kind, &report.material_args),
        &EvalOptions::default(),
    );
    let light = direction(data.theta_in, data.phi_in);
    data.samples.iter().fold((0.0, 0.0), |(m, y), s| {
        let w = s.weight * s.view.z.abs();
        let f = report.scale * bsdf.eval(light, s.view)[0];
        (m + w * f, y + w * s.value[0])
    })
}

/// Plastic data brightened towards the normal (× 1 + cos θ_out): a shape
/// no plastic follows, so the residuals alone move the energy.
fn misshapen(theta_in: f64) -> IncidenceData {
    let truth: Material = material(MaterialKind::Plastic, &[0.4, 0.4, 0.4, 0.05, 0.12]);
    let mut data = synth(&truth, theta_in, 1, 0.0, 7);
    for s in &mut data.samples {
        s.value[0] *= 1.0 + s.view.z;
    }
    data
}

fn config(energy: EnergyRule) -> FitConfig {
    FitConfig {
        gray: true,
        energy,
        ..FitConfig::new(MaterialKind::Plastic)
    }
}

#[test]
fn an_exact_energy_fit_carries_the_datas_energy_where_a_free_fit_does_not() {
    for residual in [crate::ResidualKind::Absolute, crate::ResidualKind::Log] {
        let data = misshapen(30.0);
        let fit = |energy| {
            let config = FitConfig {
                residual,
                ..config(energy)
            };
            fit_incidence(&data, &config).unwrap()
        };
        let (free, exact) = (fit(EnergyRule::Free), fit(EnergyRule::Exact));
        let (m, y) = energies(&data, &free, MaterialKind::Plastic);
        assert!(
            (m / y - 1.0).abs() > 1e-2,
            "{residual:?}: the free fit already has the data's energy ({m} against {y}): the test shows nothing"
        );
        let (m, y) = energies(&data, &exact, MaterialKind::Plastic);
        assert!(
            (m / y - 1.0).abs() < 1e-5,
            "{residual:?}: exact energy {m} against the data's {y}"
        );
        // The shape is fitted within the energy: worse than free, not far off.
        assert!(exact.cost >= free.cost * (1.0 - 1e-9));
        assert!(
            exact.cost < 10.0 * free.cost,
            "{} vs {}",
            exact.cost,
            free.cost
        );
    }
}

#[test]
fn a_model_that_describes_the_data_is_fitted_the_same_with_exact_energy() {
    let args = [0.3, 0.5, 0.2, 0.04, 0.15];
    let data = synth(&material(MaterialKind::Plastic, &args), 40.0, 3, 0.0, 3);
    let exact = fit_incidence(
        &data,
        &FitConfig {
            energy: EnergyRule::Exact,
            ..FitConfig::new(MaterialKind::Plastic)
        },
    )
    .unwrap();
    for (got, want) in exact.material_args.iter().zip(args) {
        assert!(
            (got - want).abs() < 1e-6 * want.max(0.01),
            "{got} against {want}"
        );
    }
}

#[test]
fn an_all_incidence_fit_with_exact_energy_is_nearer_each_incidences_energy() {
    let data: Vec<IncidenceData> = [10.0, 40.0, 60.0].map(misshapen).into();
    let worst = |energy| {
        let report = fit_global(&data, &config(energy)).unwrap();
        data.iter()
            .map(|d| {
                let (m, y) = energies(d, &report, MaterialKind::Plastic);
                (m / y - 1.0).abs()
            })
            .fold(0.0, f64::max)
    };
    let (free, exact) = (worst(EnergyRule::Free), worst(EnergyRule::Exact));
    assert!(
        exact < 0.5 * free,
        "worst energy misfit {exact} against free {free}"
    );
}
