//! Hints that start loading memory a pass will soon read.
//!
//! Why: the pair table's states and the solver's constraints are read in orders the
//! processor cannot predict (by slot, by colour), and each first read of one was a cache
//! miss the pass waited on. Asked for a few items ahead, the loads overlap with the work.

/// Asks the processor to start loading every cache line of `value` (a hint only: nothing is
/// read, and elsewhere than on x86-64 it does nothing).
#[inline]
pub(crate) fn lines<T: ?Sized>(value: &T) {
    #[cfg(target_arch = "x86_64")]
    {
        let start = std::ptr::from_ref(value).cast::<u8>();
        for offset in (0..size_of_val(value)).step_by(64) {
            // SAFETY: prefetching has no effect on memory or program state and never faults;
            // the address is within `value`.
            unsafe {
                std::arch::x86_64::_mm_prefetch::<{ std::arch::x86_64::_MM_HINT_T0 }>(
                    start.wrapping_add(offset).cast::<i8>(),
                );
            }
        }
    }
    #[cfg(not(target_arch = "x86_64"))]
    let _ = value;
}
