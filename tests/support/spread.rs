//! A test's independent cases run on every core. The harness runs a binary's tests side
//! by side, but a test that loops over many cases runs them one after another, and when it
//! is the last test of its binary still running, the other cores wait. Each case runs
//! under `catch_unwind`, so every failing case is told by its name, not only the first.

use std::panic::{AssertUnwindSafe, catch_unwind};
use std::sync::Mutex;
use std::sync::atomic::{AtomicUsize, Ordering};

pub use betr::fuzz::panic_message as message;

/// `check` of every item, run on as many threads as the machine has cores (no more than
/// there are items), returned in the items' order. Panics after all have run when any
/// check panicked, naming each such item (by `name`) with its panic's message.
pub fn each<T, R>(
    items: &[T],
    name: impl Fn(&T) -> String + Sync,
    check: impl Fn(&T) -> R + Sync,
) -> Vec<R>
where
    T: Sync,
    R: Send,
{
    let threads = std::thread::available_parallelism()
        .map_or(1, |n| n.get())
        .min(items.len())
        .max(1);
    let next = AtomicUsize::new(0);
    let done: Mutex<Vec<(usize, R)>> = Mutex::new(Vec::with_capacity(items.len()));
    let failed: Mutex<Vec<String>> = Mutex::new(Vec::new());
    std::thread::scope(|scope| {
        for _ in 0..threads {
            scope.spawn(|| {
                loop {
                    let i = next.fetch_add(1, Ordering::SeqCst);
                    let Some(item) = items.get(i) else { break };
                    match catch_unwind(AssertUnwindSafe(|| check(item))) {
                        Ok(result) => done.lock().unwrap().push((i, result)),
                        Err(payload) => failed.lock().unwrap().push(format!(
                            "{}: {}",
                            name(item),
                            message(payload.as_ref())
                        )),
                    }
                }
            });
        }
    });
    let failed = failed.into_inner().unwrap();
    assert!(
        failed.is_empty(),
        "{} of {} cases failed:\n{}",
        failed.len(),
        items.len(),
        failed.join("\n\n")
    );
    let mut done = done.into_inner().unwrap();
    done.sort_by_key(|(i, _)| *i);
    done.into_iter().map(|(_, r)| r).collect()
}
