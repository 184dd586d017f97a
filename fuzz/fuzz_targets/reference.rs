//! Every public entry point of the f64 reference on arbitrary scenes and samples:
//! a typed error or finite, non-NaN results (infinities only where documented).
#![no_main]

use arbitrary::Arbitrary;
use libfuzzer_sys::fuzz_target;
use misalign::reference::{self, normal, tangential};
use misalign::{Scene, ThetaRelation};

#[derive(Arbitrary, Debug)]
struct Input {
    r1: f64,
    r2: f64,
    g: f64,
    nu: f64,
    mu: f64,
    load: f64,
    phi: f64,
    length: f64,
    exact: bool,
    x: f64,
    y: f64,
}

fuzz_target!(|i: Input| {
    let _ = normal::ellipse_shape(i.phi);
    let _ = normal::theta_for_g(i.x);
    let f = tangential::axial_force_ratio(i.x);
    assert!(i.x.is_nan() || (0.0..=1.0).contains(&f));
    let Ok(mut scene) = Scene::new(i.r1, i.r2, i.g, i.nu, i.mu) else { return };
    if i.exact {
        scene = scene.with_theta_relation(ThetaRelation::Exact);
    }
    if let Ok(e) = reference::elliptic(&scene, i.load, i.phi) {
        assert!(!e.slip_ratio.is_nan() && !e.axial_force.is_nan() && !e.p0.is_nan(), "{e:?}");
        assert!(e.axial_force.abs() <= scene.friction() * i.load);
        let _ = e.traction(&scene, i.x, i.y);
        let _ = e.stick_zone(i.x);
        if let Some(phi0) = e.critical_angle {
            assert!(phi0 >= 0.0 && !phi0.is_nan());
        }
    }
    if let Ok(l) = reference::line(&scene, i.load, i.phi) {
        assert!(!l.slip_ratio.is_nan() && !l.axial_force.is_nan() && !l.critical_angle.is_nan(), "{l:?}");
        let _ = l.traction(&scene, i.y);
    }
    if let Ok(s) = scene.with_length(i.length) {
        let _ = reference::estimate(&s, i.load, i.phi);
    }
    let _ = reference::critical_angle(&scene, i.load.abs());
});
