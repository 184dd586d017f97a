//! The images' panic handlers, as macros: an image has exactly one (the no-panic images
//! take panic-never's), so the library part of this crate defines none.

/// Defines the panic handler that logs the panic through defmt and exits with
/// [`support::PANIC`](crate::support::PANIC), and a HardFault handler that logs the
/// faulting pc and exits with [`support::HARD_FAULT`](crate::support::HARD_FAULT)
/// instead of cortex-m-rt's endless loop, so that QEMU exits and says so. For the
/// firmware example, the on-target tests and the benchmark image.
#[macro_export]
macro_rules! log_panics_and_faults {
    () => {
        #[panic_handler]
        fn panic(info: &core::panic::PanicInfo) -> ! {
            $crate::support::log_panic(info)
        }

        #[$crate::cortex_m_rt::exception]
        unsafe fn HardFault(frame: &$crate::cortex_m_rt::ExceptionFrame) -> ! {
            $crate::support::log_hard_fault(frame)
        }
    };
}

/// Defines the minimal images' panic handler: exit with status 101, nothing else (no
/// logger, so that the images hold the estimator and as little else as possible).
#[macro_export]
macro_rules! exit_on_panic {
    () => {
        #[panic_handler]
        fn panic(_: &core::panic::PanicInfo) -> ! {
            $crate::io::exit(101)
        }
    };
}
