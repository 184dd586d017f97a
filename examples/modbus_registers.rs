//! Prints the Modbus register map as CSV (`misalign::modbus::registers_csv`): the
//! committed `docs/modbus/registers.csv` is its output, and `tests/modbus.rs` fails
//! when the two differ.
//!
//! ```text
//! cargo run --example modbus_registers --features modbus > docs/modbus/registers.csv
//! ```

fn main() {
    let mut csv = String::new();
    misalign::modbus::registers_csv(&mut csv).expect("a String takes every write");
    print!("{csv}");
}
