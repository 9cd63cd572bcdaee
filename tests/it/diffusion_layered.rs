//! Layered materials (DJ05 adding in frequency space + inverse Hankel transform; `specs/diffusion.md`).

use rtbake::diffusion::hankel::InverseHankel;
use rtbake::diffusion::layered::{stack_hankel, Adding, Layer, LayerStack, LayeredProfile};
use rtbake::diffusion::multipole::{Series, Slab};
use rtbake::diffusion::quadrature::radial_total;
use rtbake::diffusion::{FdrForm, RadialProfile};

fn layer(d: f64, eta: f64, sa: [f64; 3], ss: [f64; 3]) -> Layer {
    Layer { thickness_mm: d, eta, sigma_a: sa, sigma_s_prime: ss }
}

/// A skin-like three-layer stack (epidermis, upper dermis, deep dermis), air above.
fn skin3() -> LayerStack {
    LayerStack::new(
        1.0,
        1.0,
        vec![
            layer(0.25, 1.4, [0.2, 0.5, 1.2], [5.0, 6.0, 7.0]),
            layer(0.5, 1.38, [0.03, 0.1, 0.2], [2.0, 2.5, 3.0]),
            layer(3.0, 1.36, [0.01, 0.05, 0.1], [1.5, 2.0, 2.5]),
        ],
    )
    .unwrap()
}

fn thin2() -> LayerStack {
    LayerStack::new(
        1.0,
        1.2,
        vec![layer(0.4, 1.45, [0.05, 0.02, 0.3], [4.0, 3.0, 5.0]), layer(1.2, 1.3, [0.0, 0.01, 0.05], [1.0, 1.5, 2.0])],
    )
    .unwrap()
}

fn rel(a: f64, b: f64) -> f64 {
    (a - b).abs() / b.abs().max(1e-300)
}

#[test]
fn layered_integrals_equal_hankel_totals() {
    for (stack, r_max) in [(skin3(), 400.0), (thin2(), 400.0)] {
        for adding in [Adding::Symmetric, Adding::Directional] {
            let p = LayeredProfile::new(&stack, adding, Series::Exact, FdrForm::Dj05).unwrap();
            let num = radial_total(
                |r| {
                    let (a, b) = p.rt_mm2(r);
                    [a[0], a[1], a[2], b[0], b[1], b[2]]
                },
                1e-6,
                r_max,
                240,
            );
            let tr = p.total_reflectance();
            let tt = p.total_transmittance().unwrap();
            for c in 0..3 {
                assert!(rel(num[c], tr[c]) < 1e-10, "{adding:?} ch{c}: ∫R {} vs R̂(0) {}", num[c], tr[c]);
                assert!(rel(num[3 + c], tt[c]) < 1e-10, "{adding:?} ch{c}: ∫T {} vs T̂(0) {}", num[3 + c], tt[c]);
            }
        }
    }
}

#[test]
fn single_layer_stack_equals_the_multipole() {
    let stack = LayerStack::new(1.0, 1.3, vec![layer(1.5, 1.4, [0.02, 0.1, 0.4], [1.0, 2.0, 3.0])]).unwrap();
    let p = LayeredProfile::new(&stack, Adding::Symmetric, Series::Exact, FdrForm::Dj05).unwrap();
    for c in 0..3 {
        let s = Slab::new(
            stack.layers()[0].sigma_a[c],
            stack.layers()[0].sigma_s_prime[c],
            1.5,
            1.4,
            1.4 / 1.3,
            FdrForm::Dj05,
        )
        .unwrap();
        let (rt, tt) = s.totals(Series::Exact);
        assert_eq!(p.total_reflectance()[c], rt);
        assert_eq!(p.total_transmittance().unwrap()[c], tt);
        let t0 = s.transmittance_mm2(0.0, Series::Exact);
        let r0 = s.reflectance_mm2(0.0, Series::Exact);
        for r in [0.0, 0.05, 0.5, 1.0, 3.0, 10.0, 40.0] {
            let (pr, pt) = p.rt_mm2(r);
            // R(r): dipole + first image pair in real space, the other images by inverse transform.
            let rs = s.reflectance_mm2(r, Series::Exact);
            assert!((pr[c] - rs).abs() < 1e-13 * r0, "ch{c} R({r}): {} vs {rs}", pr[c]);
            // T(r) comes from the numerical inverse transform: compare with the analytic image series.
            let ts = s.transmittance_mm2(r, Series::Exact);
            assert!((pt[c] - ts).abs() < 1e-13 * t0, "ch{c} T({r}): {} vs {ts}", pt[c]);
        }
    }
}

#[test]
fn remainder_split_agrees_with_direct_inverse_transform() {
    // Independent route: inverse-transform the whole R̂stack (decays only like e^(−l₁k)) without the analytic split.
    let stack = skin3();
    let p = LayeredProfile::new(&stack, Adding::Symmetric, Series::Exact, FdrForm::Dj05).unwrap();
    let slabs = stack.slabs(FdrForm::Dj05).unwrap();
    let per_channel: Vec<Vec<Slab>> = (0..3).map(|c| slabs.iter().map(|l| l[c]).collect()).collect();
    let direct = InverseHankel::<3>::new(
        Box::new(move |k| [0, 1, 2].map(|c| stack_hankel(&per_channel[c], k, Adding::Symmetric, Series::Exact).0)),
        0.1,
        0.1,
    );
    for r in [0.2, 0.5, 1.0, 2.0, 5.0] {
        let a = p.reflectance_mm2(r);
        let b = direct.eval(r);
        for c in 0..3 {
            assert!(rel(a[c], b[c]) < 1e-8, "R({r}) ch{c}: split {} vs direct {}", a[c], b[c]);
        }
    }
}

#[test]
fn symmetric_and_directional_adding_agree_for_matched_faces_only() {
    // Matched: every layer sees the same index above and below (n = 1.4 everywhere but the layers themselves),
    // so R↑ = R↓ and T↑ = T↓ layer by layer and the two formulas coincide for two layers.
    let matched = LayerStack::new(
        1.0,
        1.0,
        vec![layer(0.3, 1.0, [0.1, 0.2, 0.4], [5.0, 6.0, 7.0]), layer(2.0, 1.0, [0.02, 0.05, 0.1], [2.0, 2.5, 3.0])],
    )
    .unwrap();
    let sym = LayeredProfile::new(&matched, Adding::Symmetric, Series::Exact, FdrForm::Dj05).unwrap();
    let dir = LayeredProfile::new(&matched, Adding::Directional, Series::Exact, FdrForm::Dj05).unwrap();
    for k in [0.0, 0.5, 3.0] {
        let (a, b) = (sym.hankel(k), dir.hankel(k));
        for c in 0..3 {
            assert!(rel(a.0[c], b.0[c]) < 1e-14 && rel(a.1[c], b.1[c]) < 1e-14, "k={k}");
        }
    }
    let unmatched = skin3();
    let sym = LayeredProfile::new(&unmatched, Adding::Symmetric, Series::Exact, FdrForm::Dj05).unwrap();
    let dir = LayeredProfile::new(&unmatched, Adding::Directional, Series::Exact, FdrForm::Dj05).unwrap();
    let (a, b) = (sym.total_reflectance(), dir.total_reflectance());
    assert!((0..3).all(|c| rel(a[c], b[c]) > 1e-3), "symmetric {a:?} vs directional {b:?}");
}

#[test]
fn adding_conserves_energy_without_absorption() {
    let stack = LayerStack::new(
        1.0,
        1.5,
        vec![layer(0.5, 1.4, [0.0; 3], [3.0, 4.0, 5.0]), layer(1.5, 1.33, [0.0; 3], [1.0, 2.0, 3.0])],
    )
    .unwrap();
    let p = LayeredProfile::new(&stack, Adding::Directional, Series::Exact, FdrForm::Dj05).unwrap();
    let (r, t) = (p.total_reflectance(), p.total_transmittance().unwrap());
    for c in 0..3 {
        assert!((r[c] + t[c] - 1.0).abs() < 1e-12, "ch{c}: R + T = {}", r[c] + t[c]);
    }
}

#[test]
fn evaluation_is_independent_of_thread_count() {
    let radii: Vec<f64> = (0..64).map(|i| 0.001 * 1.2f64.powi(i)).collect();
    let stack = skin3();
    let one = rayon::ThreadPoolBuilder::new().num_threads(1).build().unwrap().install(|| {
        let p = LayeredProfile::new(&stack, Adding::Symmetric, Series::Exact, FdrForm::Dj05).unwrap();
        (p.reflectance_many(&radii), p.transmittance_many(&radii))
    });
    let p = LayeredProfile::new(&stack, Adding::Symmetric, Series::Exact, FdrForm::Dj05).unwrap();
    let many = (p.reflectance_many(&radii), p.transmittance_many(&radii));
    assert_eq!(one, many);
}

#[test]
fn layer_stack_json_is_validated_with_field_names() {
    let ok = r#"{"eta_above": 1.0, "eta_below": 1.0, "layers": [
        {"thickness_mm": 0.25, "eta": 1.4, "sigma_a": [0.2, 0.5, 1.2], "sigma_s_prime": [5, 6, 7]},
        {"thickness_mm": 20, "eta": 1.4, "sigma_a": [0.01, 0.05, 0.1], "sigma_s_prime": [1.5, 2, 2.5]}]}"#;
    let stack = LayerStack::from_json_str(ok).unwrap();
    assert_eq!(stack.layers().len(), 2);
    // Round trip through the provenance JSON.
    assert_eq!(LayerStack::from_json_str(&stack.to_json().to_string()).unwrap(), stack);

    let bad = |text: &str, field: &str| {
        let e = LayerStack::from_json_str(text).unwrap_err();
        assert_eq!(e.param, field, "{text}: {e}");
        e
    };
    let e = bad(&ok.replace("\"thickness_mm\": 20", "\"thickness_mm\": 0.3"), "layers[1].thickness_mm");
    assert!(e.message.contains("1/sigma_t'"), "{e}");
    bad(&ok.replace("[0.01, 0.05, 0.1]", "[0.01, -0.05, 0.1]"), "layers[1].sigma_a[1]");
    bad(&ok.replace("[5, 6, 7]", "[5, 0, 7]"), "layers[0].sigma_s_prime[1]");
    bad(&ok.replace("\"eta_above\": 1.0", "\"eta_above\": 0"), "eta_above");
    bad(&ok.replace("\"eta\": 1.4, \"sigma_a\": [0.2", "\"eta\": -1.4, \"sigma_a\": [0.2"), "layers[0].eta");
    bad(r#"{"layers": []}"#, "layers");
    bad(r#"{"layers": [ {"thickness_mm": 1 "#, "layers");
    bad(&ok.replace("0.25", "NaN"), "layers");
    // NaN through the library API.
    let e = LayerStack::new(1.0, 1.0, vec![layer(1.0, 1.4, [f64::NAN, 0.1, 0.1], [1.0; 3])]).unwrap_err();
    assert_eq!(e.param, "layers[0].sigma_a[0]");
}
