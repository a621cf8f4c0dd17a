//! Giving freed memory back to the system between the batches of a long job.
//!
//! A build frees each batch's frames and tables once they are written, but glibc's
//! allocator keeps freed pages in its per-thread arenas, spread among the long-lived
//! summaries that grow between them, so a long build's RSS grew with the number of clips
//! although its heap did not. `malloc_trim` returns the free pages of every arena
//! (`madvise`, not only the top of the heap). Each trim costs the page faults of taking
//! those pages back, so it runs every `TRIM_EVERY`-th call (the measurement that set it:
//! `docs/decisions.md`, "Memory trim").

use std::sync::atomic::{AtomicUsize, Ordering};

/// Calls of [`release_free_memory`] per trim.
pub const TRIM_EVERY: usize = 8;

static CALLS: AtomicUsize = AtomicUsize::new(0);

/// Return the allocator's free pages to the system every [`TRIM_EVERY`]-th call (glibc
/// on Linux; elsewhere nothing).
pub fn release_free_memory() {
    if CALLS.fetch_add(1, Ordering::Relaxed) % TRIM_EVERY != TRIM_EVERY - 1 {
        return;
    }
    #[cfg(all(target_os = "linux", target_env = "gnu"))]
    // SAFETY: malloc_trim only walks the allocator's own free lists; no pointer is passed.
    unsafe {
        libc::malloc_trim(0);
    }
}
