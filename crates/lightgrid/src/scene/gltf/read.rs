//! The container and the bytes: a `.gltf` (JSON) or `.glb` (binary, glTF 2.0 §4.4) file, its
//! buffers (the GLB's BIN chunk, base64 `data:` URIs, files beside the document) and typed
//! reads of its accessors (§3.6.2). Every offset, length, stride and count comes from the
//! file, so each is checked against the bytes it points into before anything is allocated
//! for it; arithmetic is checked, so a huge number is an error, never a wrap.

use super::json::{Accessor, BufferView, Root};
use super::{MAX_FILE_BYTES, MAX_JSON_BYTES, MAX_VERTICES};
use std::cell::{Cell, RefCell};
use std::collections::HashMap;
use std::path::{Path, PathBuf};
use std::rc::Rc;

/// A reason a file cannot be read; the caller adds the file's name.
pub(super) type Res<T> = std::result::Result<T, String>;

/// The parsed document and its buffers' bytes.
pub(super) struct Document {
    pub root: Root,
    pub buffers: Vec<Vec<u8>>,
    /// Where relative URIs resolve (the document's folder); `None` for bytes without a file.
    base: Option<PathBuf>,
    /// What URIs have fetched (each read once) and the bytes fetched so far: buffers and
    /// images together stay within [`MAX_FILE_BYTES`], however many entries name them.
    fetched: RefCell<HashMap<String, Rc<Vec<u8>>>>,
    fetched_bytes: Cell<u64>,
}

const GLB_MAGIC: &[u8; 4] = b"glTF";
const CHUNK_JSON: u32 = 0x4E4F_534A;
const CHUNK_BIN: u32 = 0x004E_4942;

fn u32_at(bytes: &[u8], at: usize) -> Option<u32> {
    let b = bytes.get(at..at.checked_add(4)?)?;
    Some(u32::from_le_bytes([b[0], b[1], b[2], b[3]]))
}

/// Split a GLB into its JSON and (optional) BIN chunks (§4.4.3: header of magic, version 2 and
/// total length; chunks of length, type, data; JSON first).
fn split_glb(bytes: &[u8]) -> Res<(&[u8], Option<&[u8]>)> {
    let short = || "the GLB file is shorter than its header says".to_string();
    let version = u32_at(bytes, 4).ok_or_else(short)?;
    if version != 2 {
        return Err(format!(
            "GLB version {version}; only glTF 2.0 (version 2) is read"
        ));
    }
    let length = u32_at(bytes, 8).ok_or_else(short)? as usize;
    if length > bytes.len() || length < 12 {
        return Err(format!(
            "the GLB header declares {length} bytes but the file has {}",
            bytes.len()
        ));
    }
    let bytes = &bytes[..length];
    let mut chunks = Vec::new();
    let mut at = 12usize;
    while at < bytes.len() {
        let len = u32_at(bytes, at).ok_or_else(short)? as usize;
        let kind = u32_at(bytes, at + 4).ok_or_else(short)?;
        let start = at + 8;
        let end = start
            .checked_add(len)
            .filter(|&e| e <= bytes.len())
            .ok_or_else(|| {
                format!("a GLB chunk of {len} bytes at offset {at} runs past the end of the file")
            })?;
        chunks.push((kind, &bytes[start..end]));
        // Chunks are 4-byte aligned; tolerate a last chunk without its padding.
        at = end.div_ceil(4) * 4;
    }
    match chunks.first() {
        Some(&(CHUNK_JSON, json)) => {
            let bin = chunks
                .get(1)
                .filter(|(kind, _)| *kind == CHUNK_BIN)
                .map(|&(_, b)| b);
            Ok((json, bin))
        }
        _ => Err("the GLB file's first chunk is not JSON".into()),
    }
}

/// Read a file whole, refusing one larger than [`MAX_FILE_BYTES`] before reading it.
pub(super) fn read_limited(path: &Path) -> Res<Vec<u8>> {
    let meta = std::fs::metadata(path).map_err(|e| format!("{}: {e}", path.display()))?;
    if !meta.is_file() {
        return Err(format!("{} is not a regular file", path.display()));
    }
    if meta.len() > MAX_FILE_BYTES {
        return Err(format!(
            "{} has {} bytes; at most {} MiB are read",
            path.display(),
            meta.len(),
            MAX_FILE_BYTES >> 20
        ));
    }
    std::fs::read(path).map_err(|e| format!("{}: {e}", path.display()))
}

/// `asset.version` of a JSON document, read leniently (whatever else the file holds).
fn version_of(json: &[u8]) -> Option<String> {
    let v: serde_json::Value = serde_json::from_slice(json).ok()?;
    match v.get("asset")?.get("version")? {
        serde_json::Value::String(s) => Some(s.clone()),
        other => Some(other.to_string()),
    }
}

/// The JSON part of a `.gltf` or `.glb` file, read without its binary chunk (at most
/// [`MAX_JSON_BYTES`]).
fn read_json_part(path: &Path) -> Res<Vec<u8>> {
    use std::io::Read;
    let fail = |e: std::io::Error| format!("{}: {e}", path.display());
    let meta = std::fs::metadata(path).map_err(fail)?;
    if !meta.is_file() {
        return Err(format!("{} is not a regular file", path.display()));
    }
    let mut file = std::fs::File::open(path).map_err(fail)?;
    let mut head = [0u8; 20];
    let got = (&mut file).take(20).read(&mut head).map_err(fail)?;
    let (skip, len) = if got == 20 && head.starts_with(GLB_MAGIC) {
        let len = u32_at(&head, 12).unwrap_or(0);
        (20u64, u64::from(len))
    } else {
        (0, meta.len())
    };
    if len > MAX_JSON_BYTES {
        return Err(format!("{}: the JSON part is too large", path.display()));
    }
    let mut file = std::fs::File::open(path).map_err(fail)?;
    std::io::copy(&mut (&mut file).take(skip), &mut std::io::sink()).map_err(fail)?;
    let mut json = Vec::new();
    file.take(len).read_to_end(&mut json).map_err(fail)?;
    Ok(json)
}

/// The files beside the document at `path` that it names as buffers or images, resolved
/// as [`Document::fetch`] resolves them (percent-decoded, relative to the document's folder;
/// `data:` and remote URIs name no file). Read leniently: whatever of the file can be read
/// is listed, and a file that cannot be read lists nothing (loading it then fails).
pub(super) fn files_named_by(path: &Path) -> Vec<PathBuf> {
    let Ok(json) = read_json_part(path) else {
        return Vec::new();
    };
    let json = json.strip_prefix(b"\xEF\xBB\xBF").unwrap_or(&json);
    let Ok(root) = serde_json::from_slice::<serde_json::Value>(json) else {
        return Vec::new();
    };
    let base = match path.parent() {
        Some(p) if !p.as_os_str().is_empty() => p,
        _ => Path::new("."),
    };
    let mut files = Vec::new();
    for key in ["buffers", "images"] {
        let entries = root.get(key).and_then(|v| v.as_array());
        for entry in entries.into_iter().flatten() {
            let Some(uri) = entry.get("uri").and_then(|u| u.as_str()) else {
                continue;
            };
            if uri.starts_with("data:") || uri.contains("://") {
                continue;
            }
            if let Ok(rel) = percent_decode(uri) {
                if Path::new(&rel).is_relative() {
                    files.push(base.join(rel));
                }
            }
        }
    }
    files
}

/// Decode standard base64 (RFC 4648 §4; padding optional, whitespace refused).
fn base64(text: &str) -> Res<Vec<u8>> {
    let text = text.trim_end_matches('=');
    let mut out = Vec::with_capacity(text.len() / 4 * 3 + 3);
    let (mut acc, mut bits) = (0u32, 0u32);
    for c in text.bytes() {
        let v = match c {
            b'A'..=b'Z' => c - b'A',
            b'a'..=b'z' => c - b'a' + 26,
            b'0'..=b'9' => c - b'0' + 52,
            b'+' => 62,
            b'/' => 63,
            _ => return Err(format!("a data: URI holds '{}', not base64", c as char)),
        };
        acc = (acc << 6) | u32::from(v);
        bits += 6;
        if bits >= 8 {
            bits -= 8;
            out.push((acc >> bits) as u8);
            acc &= (1 << bits) - 1;
        }
    }
    Ok(out)
}

/// Percent-decoding of a relative URI (§3.3: URIs are RFC 3986, so a space is `%20`).
fn percent_decode(uri: &str) -> Res<String> {
    let b = uri.as_bytes();
    let mut out = Vec::with_capacity(b.len());
    let mut i = 0;
    while i < b.len() {
        if b[i] == b'%' {
            let hex = b
                .get(i + 1..i + 3)
                .and_then(|h| std::str::from_utf8(h).ok())
                .and_then(|h| u8::from_str_radix(h, 16).ok())
                .ok_or_else(|| format!("URI '{uri}' has a malformed %-escape"))?;
            out.push(hex);
            i += 3;
        } else {
            out.push(b[i]);
            i += 1;
        }
    }
    String::from_utf8(out).map_err(|_| format!("URI '{uri}' does not decode to UTF-8"))
}

impl Document {
    /// Parse a `.gltf` or `.glb` file's bytes; `base` is the folder relative URIs resolve in.
    pub(super) fn parse(bytes: &[u8], base: Option<&Path>) -> Res<Document> {
        let (json, bin) = if bytes.starts_with(GLB_MAGIC) {
            split_glb(bytes)?
        } else {
            (bytes, None)
        };
        if json.len() as u64 > MAX_JSON_BYTES {
            return Err(format!(
                "the JSON part has {} bytes; at most {} MiB are read",
                json.len(),
                MAX_JSON_BYTES >> 20
            ));
        }
        let json = json.strip_prefix(b"\xEF\xBB\xBF").unwrap_or(json);
        let root: Root = serde_json::from_slice(json).map_err(|e| {
            // glTF 1.0 has maps where 2.0 has arrays, so its files fail the typed parse:
            // say which version the file is rather than where the shapes differ.
            match version_of(json) {
                Some(v) if !v.starts_with('2') => {
                    format!("a glTF {v} file (asset.version '{v}'); only glTF 2.0 is read (convert it to 2.0 first, e.g. with the Khronos glTF converters)")
                }
                _ => format!("malformed JSON: {e}"),
            }
        })?;
        let version = root.asset.as_ref().map(|a| a.version.as_str());
        match version {
            Some(v) if v == "2.0" || v.starts_with("2.") => {}
            Some(v) => return Err(format!("asset.version is '{v}'; only glTF 2.0 is read")),
            None => return Err("no \"asset\" (every glTF 2.0 file has one)".into()),
        }
        let mut doc = Document {
            root,
            buffers: Vec::new(),
            base: base.map(Path::to_path_buf),
            fetched: RefCell::new(HashMap::new()),
            fetched_bytes: Cell::new(0),
        };
        let defs = std::mem::take(&mut doc.root.buffers);
        for (i, def) in defs.iter().enumerate() {
            let data: Rc<Vec<u8>> = match (&def.uri, i, bin) {
                (None, 0, Some(bin)) => Rc::new(bin.to_vec()),
                (None, _, _) => {
                    return Err(format!(
                        "buffer {i} has no uri and is not the GLB's binary chunk"
                    ))
                }
                (Some(uri), _, _) => doc.fetch(uri, &format!("buffer {i}"))?,
            };
            if (data.len() as u64) < def.byte_length {
                return Err(format!(
                    "buffer {i} declares {} bytes but holds {}",
                    def.byte_length,
                    data.len()
                ));
            }
            let kept: u64 = doc.buffers.iter().map(|b| b.len() as u64).sum();
            if kept + def.byte_length > MAX_FILE_BYTES {
                return Err(format!(
                    "the buffers declare more than {} MiB",
                    MAX_FILE_BYTES >> 20
                ));
            }
            doc.buffers.push(data[..def.byte_length as usize].to_vec());
        }
        doc.root.buffers = defs;
        Ok(doc)
    }

    /// The bytes a URI names (read once; all URIs together at most [`MAX_FILE_BYTES`]).
    pub(super) fn fetch(&self, uri: &str, what: &str) -> Res<Rc<Vec<u8>>> {
        if let Some(bytes) = self.fetched.borrow().get(uri) {
            return Ok(bytes.clone());
        }
        let bytes = Rc::new(self.fetch_uncached(uri, what)?);
        let total = self.fetched_bytes.get() + bytes.len() as u64;
        if total > MAX_FILE_BYTES {
            return Err(format!(
                "{what}: the file's buffers and images add up to more than {} MiB",
                MAX_FILE_BYTES >> 20
            ));
        }
        self.fetched_bytes.set(total);
        self.fetched
            .borrow_mut()
            .insert(uri.to_string(), bytes.clone());
        Ok(bytes)
    }

    /// The bytes a URI names: a base64 `data:` URI or a file relative to the document.
    fn fetch_uncached(&self, uri: &str, what: &str) -> Res<Vec<u8>> {
        if let Some(rest) = uri.strip_prefix("data:") {
            let (header, payload) = rest
                .split_once(',')
                .ok_or_else(|| format!("{what}: a data: URI without a ','"))?;
            if !header.ends_with(";base64") {
                return Err(format!("{what}: only base64 data: URIs are read"));
            }
            if payload.len() as u64 > MAX_FILE_BYTES / 3 * 4 {
                return Err(format!(
                    "{what}: the data: URI is larger than files read here"
                ));
            }
            return base64(payload).map_err(|e| format!("{what}: {e}"));
        }
        if uri.contains("://") {
            return Err(format!(
                "{what}: '{uri}' is a remote URI; only files beside the document are read"
            ));
        }
        let rel = percent_decode(uri).map_err(|e| format!("{what}: {e}"))?;
        let rel = Path::new(&rel);
        if rel.is_absolute() {
            return Err(format!(
                "{what}: '{uri}' is an absolute path; glTF URIs are relative to the document"
            ));
        }
        let Some(base) = &self.base else {
            return Err(format!(
                "{what}: '{uri}' is a separate file, and these bytes have no folder"
            ));
        };
        read_limited(&base.join(rel)).map_err(|e| format!("{what}: {e}"))
    }

    /// The bytes of buffer view `index`, checked against its buffer.
    pub(super) fn view(&self, index: usize, what: &str) -> Res<(&BufferView, &[u8])> {
        let view = self
            .root
            .buffer_views
            .get(index)
            .ok_or_else(|| format!("{what}: buffer view {index} does not exist"))?;
        let buffer = self.buffers.get(view.buffer).ok_or_else(|| {
            format!(
                "{what}: buffer view {index} names buffer {}, which does not exist",
                view.buffer
            )
        })?;
        let end = view
            .byte_offset
            .checked_add(view.byte_length)
            .filter(|&e| e <= buffer.len() as u64)
            .ok_or_else(|| {
                format!(
                    "{what}: buffer view {index} (offset {}, {} bytes) overruns buffer {} of {} bytes",
                    view.byte_offset,
                    view.byte_length,
                    view.buffer,
                    buffer.len()
                )
            })?;
        Ok((view, &buffer[view.byte_offset as usize..end as usize]))
    }

    fn accessor(&self, index: usize, what: &str) -> Res<&Accessor> {
        self.root
            .accessors
            .get(index)
            .ok_or_else(|| format!("{what}: accessor {index} does not exist"))
    }

    /// Accessor `index` as floats, `comps` per element (its type must have that many), with
    /// normalized integers mapped to [0, 1] or [-1, 1] (§3.11). `what` names the attribute.
    pub(super) fn read_floats(&self, index: usize, comps: usize, what: &str) -> Res<Vec<f32>> {
        let acc = self.accessor(index, what)?;
        let what = format!("{what} (accessor {index})");
        let n = components(&acc.kind)
            .ok_or_else(|| format!("{what}: type '{}' is not SCALAR or VEC2..4", acc.kind))?;
        if n != comps {
            return Err(format!(
                "{what}: type {} where {comps} components are needed",
                acc.kind
            ));
        }
        if acc.normalized && matches!(acc.component_type, UNSIGNED_INT | FLOAT) {
            return Err(format!(
                "{what}: normalized is only for 8- and 16-bit integers (§3.6.2.1)"
            ));
        }
        if acc.component_type != FLOAT && !acc.normalized {
            return Err(format!(
                "{what}: integer components that are not normalized (only floats or normalized integers are read here)"
            ));
        }
        self.read_values(acc, n, &what, |v| v as f32)
    }

    /// Accessor `index` as unsigned integers (indices: SCALAR u8, u16 or u32).
    pub(super) fn read_indices(&self, index: usize, what: &str) -> Res<Vec<u32>> {
        let acc = self.accessor(index, what)?;
        let what = format!("{what} (accessor {index})");
        if acc.kind != "SCALAR"
            || !matches!(
                acc.component_type,
                UNSIGNED_BYTE | UNSIGNED_SHORT | UNSIGNED_INT
            )
        {
            return Err(format!(
                "{what}: indices must be SCALAR unsigned bytes, shorts or ints"
            ));
        }
        self.read_values(acc, 1, &what, |v| v as u32)
    }

    /// Every component of every element, through `cast`, sparse substitutions applied.
    fn read_values<T: Copy + Default>(
        &self,
        acc: &Accessor,
        n: usize,
        what: &str,
        cast: impl Fn(f64) -> T,
    ) -> Res<Vec<T>> {
        let size = component_size(acc.component_type).ok_or_else(|| {
            format!(
                "{what}: componentType {} is not a glTF type",
                acc.component_type
            )
        })?;
        if acc.count > MAX_VERTICES as u64 {
            return Err(format!(
                "{what}: {} elements; at most {MAX_VERTICES} are read",
                acc.count
            ));
        }
        let shape = Shape {
            n,
            size,
            cast: &cast,
        };
        // Without a view the elements are zeros (§3.6.2.3), before any substitution.
        let mut out = vec![T::default(); acc.count as usize * n];
        if let Some(view) = acc.buffer_view {
            self.read_dense(acc, view, &shape, &mut out, what)?;
        }
        if let Some(sparse) = &acc.sparse {
            self.apply_sparse(acc, sparse, &shape, &mut out, what)?;
        }
        Ok(out)
    }

    /// The elements stored in buffer view `view_index` (strided), each checked in range.
    fn read_dense<T>(
        &self,
        acc: &Accessor,
        view_index: usize,
        shape: &Shape<'_, T>,
        out: &mut [T],
        what: &str,
    ) -> Res<()> {
        let (n, size) = (shape.n, shape.size);
        let (count, elem) = (acc.count as usize, n * size);
        let (view, bytes) = self.view(view_index, what)?;
        let stride = view.byte_stride.unwrap_or(elem as u64);
        if stride < elem as u64 || stride > 252 {
            return Err(format!(
                "{what}: byteStride {stride} for elements of {elem} bytes (4 to 252, at least the element)"
            ));
        }
        if count > 0 {
            let last = (count as u64 - 1)
                .checked_mul(stride)
                .and_then(|s| s.checked_add(acc.byte_offset))
                .and_then(|s| s.checked_add(elem as u64));
            if last.is_none_or(|l| l > bytes.len() as u64) {
                return Err(format!(
                    "{what}: {count} elements of {elem} bytes (stride {stride}, offset {}) overrun buffer view {view_index} of {} bytes",
                    acc.byte_offset,
                    bytes.len()
                ));
            }
        }
        let base = acc.byte_offset as usize;
        for (i, chunk) in out.chunks_exact_mut(n).enumerate() {
            let at = base + i * stride as usize;
            for (c, slot) in chunk.iter_mut().enumerate() {
                *slot = (shape.cast)(component(bytes, at + c * size, acc));
            }
        }
        Ok(())
    }

    /// Sparse substitutions (§3.6.2.3): `count` (index, element) pairs, tightly packed in
    /// their own views, each index inside the accessor.
    fn apply_sparse<T>(
        &self,
        acc: &Accessor,
        sparse: &super::json::Sparse,
        shape: &Shape<'_, T>,
        out: &mut [T],
        what: &str,
    ) -> Res<()> {
        let (n, size) = (shape.n, shape.size);
        let elem = n * size;
        if sparse.count > acc.count {
            return Err(format!(
                "{what}: {} sparse substitutions for {} elements",
                sparse.count, acc.count
            ));
        }
        let k = sparse.count as usize;
        let isize = match sparse.indices.component_type {
            UNSIGNED_BYTE => 1,
            UNSIGNED_SHORT => 2,
            UNSIGNED_INT => 4,
            t => return Err(format!("{what}: sparse index componentType {t}")),
        };
        let (_, ib) = self.view(sparse.indices.buffer_view, what)?;
        let (_, vb) = self.view(sparse.values.buffer_view, what)?;
        let fits = |off: u64, per: usize, bytes: &[u8]| {
            (k as u64)
                .checked_mul(per as u64)
                .and_then(|s| s.checked_add(off))
                .is_some_and(|e| e <= bytes.len() as u64)
        };
        if !fits(sparse.indices.byte_offset, isize, ib)
            || !fits(sparse.values.byte_offset, elem, vb)
        {
            return Err(format!(
                "{what}: sparse indices or values overrun their buffer views"
            ));
        }
        let index_acc = Accessor {
            component_type: sparse.indices.component_type,
            ..Accessor::default()
        };
        for j in 0..k {
            let at = sparse.indices.byte_offset as usize + j * isize;
            let target = component(ib, at, &index_acc) as u64;
            if target >= acc.count {
                return Err(format!(
                    "{what}: sparse index {target} is outside its {} elements",
                    acc.count
                ));
            }
            let vat = sparse.values.byte_offset as usize + j * elem;
            for c in 0..n {
                out[target as usize * n + c] = (shape.cast)(component(vb, vat + c * size, acc));
            }
        }
        Ok(())
    }
}

/// How an accessor's elements are read: components per element, bytes per component, and
/// the conversion of each component.
struct Shape<'a, T> {
    n: usize,
    size: usize,
    cast: &'a dyn Fn(f64) -> T,
}

pub(super) const UNSIGNED_BYTE: u32 = 5121;
pub(super) const UNSIGNED_SHORT: u32 = 5123;
pub(super) const UNSIGNED_INT: u32 = 5125;
pub(super) const FLOAT: u32 = 5126;

/// Components of an accessor type (matrices are not read here).
fn components(kind: &str) -> Option<usize> {
    match kind {
        "SCALAR" => Some(1),
        "VEC2" => Some(2),
        "VEC3" => Some(3),
        "VEC4" => Some(4),
        _ => None,
    }
}

fn component_size(t: u32) -> Option<usize> {
    match t {
        5120 | UNSIGNED_BYTE => Some(1),
        5122 | UNSIGNED_SHORT => Some(2),
        UNSIGNED_INT | FLOAT => Some(4),
        _ => None,
    }
}

/// One component at byte `at` (in range: the caller checked), normalized if the accessor says.
fn component(bytes: &[u8], at: usize, acc: &Accessor) -> f64 {
    let b = &bytes[at..];
    let norm = acc.normalized;
    match acc.component_type {
        5120 => {
            let v = f64::from(b[0] as i8);
            if norm {
                (v / 127.0).max(-1.0)
            } else {
                v
            }
        }
        UNSIGNED_BYTE => f64::from(b[0]) / if norm { 255.0 } else { 1.0 },
        5122 => {
            let v = f64::from(i16::from_le_bytes([b[0], b[1]]));
            if norm {
                (v / 32767.0).max(-1.0)
            } else {
                v
            }
        }
        UNSIGNED_SHORT => {
            f64::from(u16::from_le_bytes([b[0], b[1]])) / if norm { 65535.0 } else { 1.0 }
        }
        UNSIGNED_INT => f64::from(u32::from_le_bytes([b[0], b[1], b[2], b[3]])),
        _ => f64::from(f32::from_le_bytes([b[0], b[1], b[2], b[3]])),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn base64_decodes_with_and_without_padding() {
        assert_eq!(base64("TWFu").unwrap(), b"Man");
        assert_eq!(base64("TWE=").unwrap(), b"Ma");
        assert_eq!(base64("TQ").unwrap(), b"M");
        assert!(base64("TW E=").is_err());
    }

    #[test]
    fn percent_escapes_decode() {
        assert_eq!(percent_decode("a%20b.bin").unwrap(), "a b.bin");
        assert!(percent_decode("a%2").is_err());
        assert!(percent_decode("a%zz").is_err());
    }
}
