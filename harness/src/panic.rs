//! The minimal images' panic handler: exit with status 101, nothing else.

#[panic_handler]
fn panic(_: &core::panic::PanicInfo) -> ! {
    super::common::exit(101)
}
