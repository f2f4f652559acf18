//! Reading the GPU's results back in a page, which cannot block: by awaiting WebGPU's
//! promises, never by polling.

use std::cell::RefCell;
use std::future::Future;
use std::pin::Pin;
use std::rc::Rc;
use std::sync::Mutex;
use std::task::{Context, Poll, Waker};

use wasm_bindgen::JsValue;

use crate::error;

/// Submits `encoder`, whose last command fills `staging` (`MAP_READ`), and resolves to
/// `staging`'s bytes once they are on the CPU; rejects with the first WebGPU error raised
/// meanwhile.
pub(crate) async fn submit_and_read(
    queue: &wgpu::Queue,
    encoder: wgpu::CommandEncoder,
    staging: &wgpu::Buffer,
    errors: &Mutex<Vec<String>>,
) -> Result<Vec<u8>, JsValue> {
    queue.submit([encoder.finish()]);
    let bytes = map_read(staging).await?;
    if let Some(first) = errors.lock().unwrap().drain(..).next() {
        return Err(error(format!("WebGPU: {first}")));
    }
    Ok(bytes)
}

/// `staging`'s bytes (`MAP_READ`, filled by work already submitted), once on the CPU.
pub(crate) async fn map_read(staging: &wgpu::Buffer) -> Result<Vec<u8>, JsValue> {
    let mapped = Mapped::default();
    let done = mapped.clone();
    staging
        .slice(..)
        .map_async(wgpu::MapMode::Read, move |result| done.set(result));
    mapped
        .await
        .map_err(|e| error(format!("reading back from the GPU: {e}")))?;
    let bytes = staging
        .slice(..)
        .get_mapped_range()
        .map_err(|e| error(format!("reading back from the GPU: {e}")))?
        .to_vec();
    staging.unmap();
    Ok(bytes)
}

/// The outcome of `map_async`, awaited: its callback fills the slot and wakes the task.
#[derive(Clone, Default)]
struct Mapped(Rc<RefCell<Slot>>);

type MapResult = Result<(), wgpu::BufferAsyncError>;

#[derive(Default)]
struct Slot {
    result: Option<MapResult>,
    waker: Option<Waker>,
}

impl Mapped {
    fn set(&self, result: MapResult) {
        let mut slot = self.0.borrow_mut();
        slot.result = Some(result);
        if let Some(waker) = slot.waker.take() {
            waker.wake();
        }
    }
}

impl Future for Mapped {
    type Output = MapResult;

    fn poll(self: Pin<&mut Self>, cx: &mut Context<'_>) -> Poll<Self::Output> {
        let mut slot = self.0.borrow_mut();
        match slot.result.take() {
            Some(result) => Poll::Ready(result),
            None => {
                slot.waker = Some(cx.waker().clone());
                Poll::Pending
            }
        }
    }
}
