//! Where a command's wall time goes before its first ray and after its last: each phase timed
//! from the start of `main`, printed by `raywave render --stats`. A small job's time is mostly
//! here, not in its rays.

use std::fmt::Write;
use std::sync::OnceLock;
use std::time::Instant;

/// When `main` started.
static START: OnceLock<Instant> = OnceLock::new();

/// Notes the start of `main`; the first call wins.
pub fn start() {
    START.get_or_init(Instant::now);
}

/// Phases timed one after another, the first from the start of `main`.
pub struct Phases {
    last: Instant,
    done: Vec<(&'static str, f64)>,
}

impl Phases {
    /// Phases whose first begins when `main` started.
    pub fn since_main() -> Phases {
        Phases {
            last: *START.get_or_init(Instant::now),
            done: Vec::new(),
        }
    }

    /// Ends the current phase, named `name`, and starts the next.
    pub fn mark(&mut self, name: &'static str) {
        let now = Instant::now();
        self.done.push((name, (now - self.last).as_secs_f64()));
        self.last = now;
    }

    /// Seconds from the start of `main` to the end of phase `name` (the sum up to it).
    pub fn until(&self, name: &str) -> Option<f64> {
        let mut sum = 0.0;
        self.done.iter().find_map(|&(n, s)| {
            sum += s;
            (n == name).then_some(sum)
        })
    }

    /// The phases as a table in milliseconds, with the time from `main` to the first ray.
    pub fn table(&self, first_ray_after: &str) -> String {
        let mut out = format!("{:<28} {:>10}\n", "phase", "ms");
        for &(name, seconds) in &self.done {
            let _ = writeln!(out, "{name:<28} {:>10.3}", seconds * 1e3);
        }
        if let Some(s) = self.until(first_ray_after) {
            let _ = writeln!(
                out,
                "first ray {:.3} ms after main started (process start and dynamic linking before \
                 main are not counted)",
                s * 1e3
            );
        }
        out
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn phases_add_up_to_the_time_until_each() {
        let mut p = Phases::since_main();
        p.mark("a");
        std::thread::sleep(std::time::Duration::from_millis(2));
        p.mark("b");
        let (a, b) = (p.until("a").unwrap(), p.until("b").unwrap());
        assert!(b >= a + 0.002, "{a} {b}");
        assert_eq!(p.until("c"), None);
        let table = p.table("b");
        assert!(
            table.contains("first ray") && table.lines().count() == 4,
            "{table}"
        );
    }
}
