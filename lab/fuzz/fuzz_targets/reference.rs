//! Every public entry point of the f64 reference on structured scenes and samples
//! (extreme values: fuzz_targets/extreme.rs): a typed error or results with no NaN
//! in any field, |F| <= mu P and d <= b (infinities only where documented).
#![no_main]


use arbitrary::Arbitrary;
use misalign_fuzz::X64;
use libfuzzer_sys::fuzz_target;
use misalign::reference::{self, normal, tangential};
use misalign::{Scene, ThetaRelation};

#[derive(Arbitrary, Debug)]
struct Input {
    r1: X64,
    r2: X64,
    g: X64,
    nu: X64,
    mu: X64,
    load: X64,
    phi: X64,
    length: X64,
    exact: bool,
    x: X64,
    y: X64,
}

fuzz_target!(|i: Input| {
    let (x, y) = (i.x.0, i.y.0);
    let _ = normal::ellipse_shape(i.phi.0);
    let _ = normal::theta_for_g(x);
    let f = tangential::axial_force_ratio(x);
    assert!(x.is_nan() || (0.0..=1.0).contains(&f));
    let Ok(mut scene) = Scene::new(i.r1.0, i.r2.0, i.g.0, i.nu.0, i.mu.0) else {
        return;
    };
    if i.exact {
        scene = scene.with_theta_relation(ThetaRelation::Exact);
    }
    assert!(scene.effective_radius() > 0.0);
    let (load, phi, mu) = (i.load.0, i.phi.0, scene.friction());
    if let Ok(e) = reference::elliptic(&scene, load, phi) {
        let s = e.shape;
        let fields = [
            s.theta,
            s.kprime,
            s.m,
            s.n,
            e.a,
            e.b,
            e.p0,
            e.pstar,
            e.p0star,
            e.slip_ratio,
            e.d,
            e.axial_force,
            e.critical_load,
        ];
        assert!(fields.iter().all(|v| !v.is_nan()), "{e:?}");
        assert!(e.axial_force.abs() <= mu * load && e.d <= e.b, "{e:?}");
        let _ = e.traction(&scene, x, y);
        let _ = e.stick_zone(x);
        let _ = e.pressure(x, y);
        if let Some(phi0) = e.critical_angle {
            assert!(phi0 >= 0.0 && !phi0.is_nan());
        }
    }
    if let Ok(l) = reference::line(&scene, load, phi) {
        let fields = [
            l.radius,
            l.b,
            l.p0,
            l.pstar,
            l.p0star,
            l.slip_ratio,
            l.d,
            l.axial_force,
            l.critical_angle.unwrap_or(0.0),
            l.critical_load,
        ];
        assert!(fields.iter().all(|v| !v.is_nan()), "{l:?}");
        assert!(l.axial_force.abs() <= mu * load && l.d <= l.b, "{l:?}");
        let _ = l.traction(&scene, y);
        let _ = l.stick_zone();
    }
    if let Ok(s) = scene.with_length(i.length.0)
        && let Ok(e) = reference::estimate(&s, load, phi)
    {
        assert!(
            !e.slip_ratio().is_nan() && !e.axial_force(&s).is_nan(),
            "{e:?}"
        );
    }
    let _ = reference::critical_angle(&scene, load.abs());
});
