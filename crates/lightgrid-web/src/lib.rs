//! lightgrid's viewer as a web page: the functions the page's JavaScript (`page/index.html`)
//! calls, on wasm32 only (on other targets this crate is empty). The app itself is the
//! native viewer's (`lightgrid_viewer::web` is the seam); `scripts/build-web` builds the page
//! into `target/web-page/`, which any static server can host.
//!
//! - `start(query)`: open the scene and start rendering into a canvas appended to the body,
//!   with the page address's query (`?scene=robots-many&pipeline=tiled_deferred&...`);
//! - `status()`: the app's state as JSON (pipeline, frame, settled frames, message);
//! - `request_screenshot(name)` / `take_screenshot(name)`: the shown frame (without the
//!   panel) as a PNG, read back without waiting;
//! - `open_file(name, bytes)`: a glTF file from the page's picker or a drop, opened through
//!   the same loader as a path;
//! - `take_download()`: a screenshot the user took, which the page downloads;
//! - `spot(name)`: where a panel widget is, for tests that click it;
//! - `fatal()`: the error that ended the app, if any.

#[cfg(target_arch = "wasm32")]
mod page {
    use lightgrid_viewer::web::{self, PageOptions, SHARED};
    use wasm_bindgen::prelude::*;

    #[wasm_bindgen]
    pub async fn start(query: String) -> Result<(), JsValue> {
        let run = async {
            let opts = PageOptions::from_query(&query)?;
            web::start(opts).await
        };
        run.await.map_err(|e| {
            let message = format!("{e:#}");
            web::console_error(&format!("lightgrid: {message}"));
            SHARED.with(|s| s.borrow_mut().fatal = Some(message.clone()));
            JsValue::from_str(&message)
        })
    }

    #[wasm_bindgen]
    pub fn status() -> String {
        SHARED.with(|s| s.borrow().status.clone())
    }

    #[wasm_bindgen]
    pub fn fatal() -> Option<String> {
        SHARED.with(|s| s.borrow().fatal.clone())
    }

    #[wasm_bindgen]
    pub fn request_screenshot(name: String) {
        SHARED.with(|s| s.borrow_mut().shot_requests.push(name));
    }

    /// The PNG once taken (None until then); an error if it could not be.
    #[wasm_bindgen]
    pub fn take_screenshot(name: String) -> Result<Option<Vec<u8>>, JsValue> {
        SHARED.with(|s| match s.borrow_mut().shots.remove(&name) {
            None => Ok(None),
            Some(Ok(png)) => Ok(Some(png)),
            Some(Err(e)) => Err(JsValue::from_str(&e)),
        })
    }

    /// Open a glTF file (its name and bytes: the page's file picker or a drop) on the next
    /// frame; `status().message` says why not when it cannot be.
    #[wasm_bindgen]
    pub fn open_file(name: String, bytes: Vec<u8>) {
        SHARED.with(|s| s.borrow_mut().files.push((name, bytes)));
    }

    /// The next screenshot the user took (F12, P, the panel's button), as [name, PNG], for
    /// the page to download; None when there is none.
    #[wasm_bindgen]
    pub fn take_download() -> Option<js_sys::Array> {
        let (name, png) = SHARED.with(|s| s.borrow_mut().downloads.pop())?;
        let pair = js_sys::Array::new();
        pair.push(&JsValue::from_str(&name));
        pair.push(&js_sys::Uint8Array::from(png.as_slice()));
        Some(pair)
    }

    #[wasm_bindgen]
    pub fn spot(name: String) -> Option<Vec<f32>> {
        SHARED.with(|s| s.borrow().spots.get(&name).map(|r| r.to_vec()))
    }
}
