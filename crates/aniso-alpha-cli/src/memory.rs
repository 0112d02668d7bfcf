//! The process's allocator settings: one glibc malloc arena, and the free
//! pages handed back between the stages of a detection.
//!
//! glibc's malloc attaches each new thread to an arena of its own (up to
//! eight per core; a finished thread's arena goes to the next), and memory
//! freed into one arena serves only that arena's later requests. A
//! detection allocates its working buffers on every worker thread in turn
//! (the orientations' triangulations and faces, then the incidences,
//! candidates and claims of the assembly), so each arena keeps the
//! high-water mark of its own threads, and the peak resident memory is
//! their sum. With one arena,
//! every thread reuses what any thread freed. On the corpus this lowers
//! the peak RSS by a third on most scans (12–49%) at the same wall time
//! (BENCHMARKS.md, "One malloc arena"); malloc and free take under 1% of
//! the cycles of a detection, so the one lock they share is rarely
//! contended. Small requests still come from glibc's lock-free per-thread
//! cache.
//!
//! Freed memory inside the heap stays resident until glibc trims it, and
//! glibc trims only the heap's top: a phase's buffers freed below a live
//! one (the estimate's neighbourhoods under the cloud, the scan's
//! triangulations under the union) stay in the peak of what follows. The
//! program hands the free pages back after the estimate and after the
//! scan ([`release_free`]), the two that free the most: 16 and 14 MiB of a
//! depth frame's 28 (mOSD learn 17), 6 and 8 of an airborne tile's 18 (the
//! AHN train tile). What the assembly's stages free, the next one mostly
//! reuses below the peak of the scan: handing it back too (eight more
//! calls) kept the peaks within a run's spread and cost
//! 15–20 ms of a depth frame's 0.39 s, the pages faulted in again by the
//! next stage (BENCHMARKS.md, "Candidates found again").
//!
//! Only the command-line program does this: the Python extension lives in
//! the interpreter's process, whose allocator is not its to tune. A user's
//! own arena setting (`MALLOC_ARENA_MAX`, or `arena_max` in
//! `GLIBC_TUNABLES`) is left as it is: it is also how the many-core
//! benchmark (`scripts/device_scaling.sh`) times glibc's default beside
//! this one.

/// Limits glibc's malloc to one arena, unless the environment sets the
/// arena count. Called first in `main`, before any thread exists.
///
/// Not tested by a unit test: glibc's `mallopt` answers 1 for any
/// parameter, known or not, and has no reading back; the effect is the
/// peak RSS measured in BENCHMARKS.md.
#[cfg(all(target_os = "linux", target_env = "gnu"))]
#[allow(unsafe_code)]
pub fn one_arena() {
    let tunables = std::env::var("GLIBC_TUNABLES").unwrap_or_default();
    if std::env::var_os("MALLOC_ARENA_MAX").is_some() || tunables.contains("arena_max") {
        return;
    }
    // SAFETY: mallopt only sets a parameter of glibc's allocator, and may
    // be called at any time; had it no effect, the default arenas would
    // stay, which is correct too, only larger.
    unsafe {
        libc::mallopt(libc::M_ARENA_MAX, 1);
    }
}

/// Limits glibc's malloc to one arena: without glibc, nothing to set.
#[cfg(not(all(target_os = "linux", target_env = "gnu")))]
pub fn one_arena() {}

/// Hands the heap's free pages back to the system (glibc's
/// `malloc_trim(0)`), so that what a stage freed is not resident in the
/// next stage's peak.
#[cfg(all(target_os = "linux", target_env = "gnu"))]
#[allow(unsafe_code)]
pub fn release_free() {
    // SAFETY: malloc_trim only returns free memory of glibc's allocator to
    // the system; live allocations are untouched, and it may be called at
    // any time from any thread.
    unsafe {
        libc::malloc_trim(0);
    }
}

/// Hands the heap's free pages back: without glibc, nothing to do.
#[cfg(not(all(target_os = "linux", target_env = "gnu")))]
pub fn release_free() {}
