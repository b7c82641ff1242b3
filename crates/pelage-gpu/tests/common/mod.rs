//! What the GPU test files share: opening the adapter, or skipping.

use pelage_gpu::GpuContext;
use std::sync::OnceLock;

/// The headless adapter; without one the tests are skipped with a message,
/// unless `PELAGE_REQUIRE_GPU` is set (CI), where that is a failure.
pub fn open_headless() -> Option<GpuContext> {
    match GpuContext::headless() {
        Ok(ctx) => Some(ctx),
        Err(e) if std::env::var_os("PELAGE_REQUIRE_GPU").is_some() => {
            panic!(
                "PELAGE_REQUIRE_GPU is set and there is no adapter: {}",
                with_causes(&e)
            )
        }
        Err(e) => {
            eprintln!("SKIPPED: no GPU adapter ({})", with_causes(&e));
            None
        }
    }
}

/// An error and its causes, "a: b: c".
pub fn with_causes(error: &dyn std::error::Error) -> String {
    let mut text = error.to_string();
    let mut cause = error.source();
    while let Some(e) = cause {
        text.push_str(": ");
        text.push_str(&e.to_string());
        cause = e.source();
    }
    text
}

/// The test binary's one GPU context (see [`open_headless`]).
#[allow(dead_code)] // render.rs keeps the context beside its renderer instead
pub fn gpu() -> Option<&'static GpuContext> {
    static GPU: OnceLock<Option<GpuContext>> = OnceLock::new();
    GPU.get_or_init(open_headless).as_ref()
}
