//! The monitor example's input files (`misalign_cli::monitor_input`): scene and trace.

use misalign_cli::monitor_input as input;

#[test]
fn a_trace_becomes_samples_on_the_nodes_wrapping_clock() {
    let csv = "t,P,phi,V,F\n0,2000,1e-4,1.5,\n1.5,2100,-2e-4,,300\n4294967.3,2200,x,2,\n";
    let samples = input::read_trace(csv.as_bytes()).unwrap();
    assert_eq!(samples.len(), 3);
    assert_eq!(
        (
            samples[0].time_ms,
            samples[0].load,
            samples[0].speed,
            samples[0].axial_force
        ),
        (0, 2000.0, Some(1.5), None)
    );
    // An empty V is "not measured" (the nominal speed), not a fault.
    assert_eq!(
        (
            samples[1].time_ms,
            samples[1].phi,
            samples[1].speed,
            samples[1].axial_force
        ),
        (1500, -2e-4, None, Some(300.0))
    );
    // 4294967.3 s is past 2^32 ms: the counter wraps; an unreadable angle is a NaN, which
    // the monitor counts as a sensor fault.
    assert_eq!(samples[2].time_ms, 4);
    assert!(samples[2].phi.is_nan());
}

#[test]
fn a_trace_without_its_columns_is_refused() {
    assert!(input::read_trace("t,P\n0,1\n".as_bytes()).is_err());
    assert!(input::read_trace("t,P,phi\nnope,1,2\n".as_bytes()).is_err());
}

#[test]
fn a_scene_file_gives_the_scene_with_its_length() {
    let scene =
        input::read_scene("mu,nu,G,R2,R1,length\n0.3,0.3,79.3e9,inf,0.05,0.02\n".as_bytes())
            .unwrap();
    assert!(scene.is_plane());
    assert_eq!(
        (scene.r1(), scene.friction(), scene.length()),
        (0.05, 0.3, Some(0.02))
    );
    assert!(input::read_scene("R1,R2,G,nu\n0.05,0.05,79.3e9,0.3\n".as_bytes()).is_err());
    assert!(input::read_scene("R1,R2,G,nu,mu\n0.05,0.05,79.3e9,0.7,0.3\n".as_bytes()).is_err());
}
