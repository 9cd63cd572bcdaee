//! The separable fit (thesis eq. 6.1–6.3): recovery of known parameters, never worse than Table 6.1 under the
//! recorded objective, any `RadialProfile` as target, separability of the target.

use rtbake::diffusion::materials;
use rtbake::diffusion::sum_of_gaussians::{deon6, SumOfGaussians};
use rtbake::diffusion::{FdrForm, RadialProfile};
use rtbake::separable::fit::{
    falloff_at_width, first_singular_value_energy, fit, objective, ObjectiveSpec, TargetKernel, Weighting,
};
use rtbake::separable::{SeparableParams, PUBLISHED, TABLE_6_1};

fn assert_recovers(known: SeparableParams, spec: &ObjectiveSpec) {
    let target = TargetKernel::from_separable(&known, spec).unwrap();
    let r = fit(&target).unwrap();
    for c in 0..3 {
        assert!(
            (r.params.strength[c] - known.strength[c]).abs() < 1e-4,
            "strength {c}: {:?} vs {:?}",
            r.params.strength,
            known.strength
        );
        assert!(
            (r.params.falloff[c] - known.falloff[c]).abs() < 1e-4,
            "falloff {c}: {:?} vs {:?}",
            r.params.falloff,
            known.falloff
        );
    }
    assert!(r.objective() < 1e-12 * r.objective_table_6_1().max(1.0), "{}", r.objective());
}

#[test]
fn recovers_known_parameters_from_a_synthetic_target() {
    let spec = ObjectiveSpec::default();
    assert_recovers(TABLE_6_1, &spec);
    assert_recovers(PUBLISHED, &spec);
    assert_recovers(SeparableParams { strength: [0.93, 0.55, 0.35], falloff: [0.81, 0.24, 0.6] }, &spec);
    // Area weighting.
    let area = ObjectiveSpec { weighting: Weighting::Area, ..spec };
    assert_recovers(SeparableParams { strength: [0.7, 0.95, 0.4], falloff: [0.5, 0.3, 0.9] }, &area);
    // Another width and a coarser, uniform grid.
    let other = ObjectiveSpec { width: 0.02, grid_nodes: 31, grid_exponent: 1.0, pixel_mm: 0.1, ..spec };
    assert_recovers(SeparableParams { strength: [0.62, 0.81, 0.47], falloff: [1.3, 0.42, 0.17] }, &other);
}

#[test]
fn fit_to_deon6_is_not_worse_than_table_6_1() {
    let spec = ObjectiveSpec::default();
    let target = TargetKernel::from_profile(&deon6(), &spec, "deon6").unwrap();
    let r = fit(&target).unwrap();
    assert!(r.objective() <= r.objective_table_6_1(), "{} vs {}", r.objective(), r.objective_table_6_1());
    for c in 0..3 {
        assert!(r.objective_per_channel[c] <= r.table_6_1_per_channel[c]);
        assert!((0.0..=1.0).contains(&r.params.strength[c]) && r.params.falloff[c] >= 0.0);
    }
    // The reported values are the objective of the reported parameters.
    let again = objective(&target, &r.params);
    assert_eq!(again, r.objective_per_channel);
    assert_eq!(objective(&target, &TABLE_6_1), r.table_6_1_per_channel);
    // A local minimum: nudging any parameter does not improve it.
    for c in 0..3 {
        for (dt, df) in [(1e-3, 0.0), (-1e-3, 0.0), (0.0, 1e-3), (0.0, -1e-3)] {
            let mut p = r.params;
            p.strength[c] = (p.strength[c] + dt).clamp(0.0, 1.0);
            p.falloff[c] = (p.falloff[c] + df).max(0.0);
            assert!(objective(&target, &p)[c] >= r.objective_per_channel[c] * (1.0 - 1e-12));
        }
    }
    // Deterministic.
    assert_eq!(fit(&target).unwrap(), r);
}

#[test]
fn only_width_times_falloff_matters_and_table_6_1_is_scored_at_its_own_width() {
    let spec = ObjectiveSpec::default();
    let target = TargetKernel::from_profile(&deon6(), &spec, "deon6").unwrap();
    let wide = ObjectiveSpec { width: 0.02, ..spec };
    let target_wide = TargetKernel::from_profile(&deon6(), &wide, "deon6").unwrap();
    assert_eq!(target.values, target_wide.values, "the target does not depend on the kernel's width");
    let moved = SeparableParams {
        strength: TABLE_6_1.strength,
        falloff: TABLE_6_1.falloff.map(|f| falloff_at_width(f, 0.014, 0.02)),
    };
    let a = objective(&target, &TABLE_6_1);
    let b = objective(&target_wide, &moved);
    for c in 0..3 {
        assert!((a[c] - b[c]).abs() <= 1e-9 * a[c], "{a:?} vs {b:?}");
    }
    let r = fit(&target_wide).unwrap();
    assert!(r.objective() <= r.objective_table_6_1());
    assert_eq!(r.table_6_1_per_channel, a);
}

#[test]
fn area_weighting_is_a_quadrature_of_the_integral() {
    // With area weights the objective approximates eq. 6.2's integral, so it barely depends on the node law.
    let p = SeparableParams { strength: [0.9, 0.8, 0.7], falloff: [0.9, 0.5, 0.3] };
    let value = |exponent: f64, nodes: usize| -> f64 {
        let spec = ObjectiveSpec {
            weighting: Weighting::Area,
            grid_exponent: exponent,
            grid_nodes: nodes,
            pixel_mm: 0.3,
            ..ObjectiveSpec::default()
        };
        let t = TargetKernel::from_profile(&deon6(), &spec, "deon6").unwrap();
        objective(&t, &p).iter().sum()
    };
    let fine = value(2.0, 201);
    assert!((value(1.5, 201) / fine - 1.0).abs() < 0.01, "{} vs {fine}", value(1.5, 201));
    // The plain sum does depend on it (that is its purpose: more samples near 0 weigh more).
    let plain = |exponent: f64| -> f64 {
        let spec = ObjectiveSpec { grid_exponent: exponent, ..ObjectiveSpec::default() };
        let t = TargetKernel::from_profile(&deon6(), &spec, "deon6").unwrap();
        objective(&t, &p).iter().sum()
    };
    assert!((plain(1.0) / plain(2.0) - 1.0).abs() > 0.1);
}

#[test]
fn any_radial_profile_is_a_target() {
    let spec = ObjectiveSpec { grid_nodes: 31, ..ObjectiveSpec::default() };
    let skin1 = materials::find("skin1").unwrap().dipole(FdrForm::default());
    let profile: &dyn RadialProfile = &skin1;
    let target = TargetKernel::from_profile(profile, &spec, "skin1 dipole").unwrap();
    let r = fit(&target).unwrap();
    assert!(r.objective().is_finite() && r.objective() <= r.objective_table_6_1());
    // A grey target (the same profile in every channel) gives the same parameters in every channel.
    let grey = SumOfGaussians { variances_mm2: vec![0.0064, 0.3], weights: vec![[0.3; 3], [0.7; 3]] };
    let t = TargetKernel::from_profile(&grey, &spec, "grey").unwrap();
    let g = fit(&t).unwrap();
    for c in 1..3 {
        assert!((g.params.strength[c] - g.params.strength[0]).abs() < 1e-9);
        assert!((g.params.falloff[c] - g.params.falloff[0]).abs() < 1e-9);
    }
}

#[test]
fn a_target_with_no_energy_is_refused() {
    let empty = SumOfGaussians { variances_mm2: vec![1.0], weights: vec![[1.0, 0.0, 1.0]] };
    let e = TargetKernel::from_profile(&empty, &ObjectiveSpec::default(), "empty").unwrap_err();
    assert!(e.to_string().contains("green"), "{e}");
}

#[test]
fn skin_kernels_are_mostly_but_not_exactly_separable() {
    let spec = ObjectiveSpec::default();
    let e = first_singular_value_energy(&deon6(), &spec).unwrap();
    for c in 0..3 {
        assert!(e[c] > 0.5 && e[c] < 1.0 - 1e-6, "{e:?}");
    }
    // A single Gaussian is exactly separable.
    let g = SumOfGaussians { variances_mm2: vec![0.5], weights: vec![[1.0; 3]] };
    let eg = first_singular_value_energy(&g, &spec).unwrap();
    assert!(eg.iter().all(|v| (v - 1.0).abs() < 1e-9), "{eg:?}");
}
