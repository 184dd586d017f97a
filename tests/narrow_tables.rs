//! A scene that declares a narrower range of misalignment links fewer table rows
//! (less flash for a narrower range): the rows are copied
//! at compile time, so the full tables are not in the image.

use misalign::float::octave::{OctaveTable, Row, WIDE, narrow_rows};
use misalign::float::{EllipticScene, Tables};
use misalign::float::{G_OF_THETA_ROWS, THETA_OF_G_ROWS};
use misalign::{Error, Scene};

// theta from 2^-20 (1e-6 rad) to 2^-6 (0.016 rad): 14 octaves of g instead of 33.
static G_ROWS: [Row<WIDE>; 14] = narrow_rows(&G_OF_THETA_ROWS, 12);
// g0 from 2^-14 to 2^-4: 10 octaves of theta(g) instead of 28.
static THETA_ROWS: [Row<WIDE>; 10] = narrow_rows(&THETA_OF_G_ROWS, 13);

const NARROW: Tables<'static> = Tables {
    g: OctaveTable::new(-20, &G_ROWS),
    theta_of_g: OctaveTable::new(-14, &THETA_ROWS),
};

#[test]
fn narrow_tables_give_the_same_answers_in_range_and_errors_outside() {
    let scene = Scene::DEMO;
    let full = EllipticScene::new(&scene).unwrap();
    let narrow = EllipticScene::with_tables(&scene, NARROW).unwrap();
    for load in [20.0, 100.0, 1e3, 5e3] {
        for phi in [1e-6, 3e-5, 2e-4, 1e-3, 1.5e-2] {
            assert_eq!(
                full.estimate(load, phi),
                narrow.estimate(load, phi),
                "{load} {phi}"
            );
        }
    }
    // Outside the declared range: a typed error, not an extrapolation.
    assert_eq!(narrow.estimate(1e3, 1e-7), Err(Error::OutOfRange));
    assert_eq!(narrow.estimate(1e3, 0.1), Err(Error::OutOfRange));
    assert_eq!(narrow.estimate(1e9, 1e-3), Err(Error::OutOfRange));
    let bytes = core::mem::size_of_val(&G_ROWS) + core::mem::size_of_val(&THETA_ROWS);
    let full_bytes =
        core::mem::size_of_val(&G_OF_THETA_ROWS) + core::mem::size_of_val(&THETA_OF_G_ROWS);
    assert_eq!((bytes, full_bytes), (1536, 3904));
}
