//! What every `cargo bench` harness shares (included by `#[path]`, not a bench of its own).

/// The value of the environment variable `name` as a number, or `default` when it is unset or
/// not a number.
pub fn env(name: &str, default: usize) -> usize {
    std::env::var(name)
        .ok()
        .and_then(|v| v.parse().ok())
        .unwrap_or(default)
}
