//! The GPU connection: instance, adapter, device and queue.

use crate::GpuError;
use std::sync::{Arc, Mutex};

/// An open GPU device. One per process is enough; renderers share it.
#[derive(Debug)]
pub struct GpuContext {
    /// The wgpu device.
    pub device: wgpu::Device,
    /// Its queue.
    pub queue: wgpu::Queue,
    adapter: wgpu::AdapterInfo,
    raw_adapter: wgpu::Adapter,
    /// The first error wgpu reported outside an error scope (out of
    /// memory, a limit passed), kept for [`Self::check`]. wgpu's default
    /// is to panic, which would end the program with a backtrace instead
    /// of a message.
    errors: Arc<Mutex<Option<String>>>,
}

impl GpuContext {
    /// Opens the best adapter for offscreen rendering. `WGPU_BACKEND`,
    /// `WGPU_ADAPTER_NAME` and `WGPU_POWER_PREF` choose among several.
    pub fn headless() -> Result<Self, GpuError> {
        let instance =
            wgpu::Instance::new(wgpu::InstanceDescriptor::new_without_display_handle_from_env());
        Self::open(&instance, None)
    }

    /// Opens the best adapter that can draw into `surface` (a window's),
    /// made by `instance`; configure the surface with [`Self::device`]
    /// afterwards. The same environment variables apply.
    pub fn for_surface(
        instance: &wgpu::Instance,
        surface: &wgpu::Surface<'_>,
    ) -> Result<Self, GpuError> {
        Self::open(instance, Some(surface))
    }

    /// The caller's own adapter, device and queue (an engine's, a game's),
    /// for uploading and drawing with pelage there (docs/embedding.md).
    /// wgpu's handles are shared, not copied. Unlike [`Self::headless`] it
    /// installs no handler for uncaptured errors on the device: that stays
    /// the caller's, and [`Self::check`] reports nothing.
    pub fn wrap(adapter: &wgpu::Adapter, device: &wgpu::Device, queue: &wgpu::Queue) -> Self {
        Self {
            device: device.clone(),
            queue: queue.clone(),
            adapter: adapter.get_info(),
            raw_adapter: adapter.clone(),
            errors: Arc::new(Mutex::new(None)),
        }
    }

    fn open(
        instance: &wgpu::Instance,
        surface: Option<&wgpu::Surface<'_>>,
    ) -> Result<Self, GpuError> {
        let options = wgpu::RequestAdapterOptions {
            power_preference: wgpu::PowerPreference::from_env()
                .unwrap_or(wgpu::PowerPreference::HighPerformance),
            force_fallback_adapter: false,
            compatible_surface: surface,
            ..Default::default()
        };
        let adapter =
            pollster::block_on(instance.request_adapter(&options)).map_err(GpuError::NoAdapter)?;
        let info = adapter.get_info();
        let (device, queue) = pollster::block_on(adapter.request_device(&wgpu::DeviceDescriptor {
            label: Some("pelage"),
            required_features: wgpu::Features::empty(),
            // Everything the adapter offers: a million preview curves need a
            // vertex buffer of a few hundred MB.
            required_limits: adapter.limits(),
            ..Default::default()
        }))
        .map_err(|error| GpuError::Device {
            adapter: info.name.clone(),
            error,
        })?;
        let errors = Arc::new(Mutex::new(None));
        let sink = errors.clone();
        device.on_uncaptured_error(Arc::new(move |error: wgpu::Error| {
            let mut first = sink.lock().unwrap_or_else(|e| e.into_inner());
            if first.is_none() {
                *first = Some(match error {
                    wgpu::Error::OutOfMemory { .. } => {
                        "the GPU ran out of memory; draw a smaller image, or fewer layers, hairs or texels".to_string()
                    }
                    // wgpu's message spans lines ("Caused by: …"); errors
                    // print on one.
                    error => error
                        .to_string()
                        .lines()
                        .map(str::trim)
                        .filter(|l| !l.is_empty() && *l != "Caused by:")
                        .collect::<Vec<_>>()
                        .join(": "),
                });
            }
        }));
        Ok(Self {
            device,
            queue,
            adapter: info,
            raw_adapter: adapter,
            errors,
        })
    }

    /// The first error the GPU reported since the last check (an
    /// allocation that failed, a limit passed), as a [`GpuError`]. Every
    /// read-back checks it, so a picture drawn with a failed resource is
    /// an error, never a blank image.
    pub fn check(&self) -> Result<(), GpuError> {
        let mut first = self.errors.lock().unwrap_or_else(|e| e.into_inner());
        match first.take() {
            Some(message) => Err(GpuError::Failed {
                adapter: self.adapter_name(),
                message,
            }),
            None => Ok(()),
        }
    }

    /// The adapter, e.g. for a surface's capabilities.
    pub fn adapter(&self) -> &wgpu::Adapter {
        &self.raw_adapter
    }

    /// The adapter in words: name and backend, e.g. `llvmpipe (LLVM 15.0.6,
    /// 256 bits) (Vulkan)`.
    pub fn adapter_name(&self) -> String {
        format!("{} ({:?})", self.adapter.name, self.adapter.backend)
    }

    /// Whether the adapter is a CPU (software) one, such as lavapipe.
    pub fn is_software(&self) -> bool {
        self.adapter.device_type == wgpu::DeviceType::Cpu
    }

    /// Waits for all work submitted so far to finish.
    pub fn wait(&self) -> Result<(), GpuError> {
        self.device
            .poll(wgpu::PollType::wait_indefinitely())
            .map(|_| ())
            .map_err(|e| GpuError::Readback(e.into()))
    }
}
