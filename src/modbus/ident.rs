//! Function 43, MEI type 14: read device identification. Basic objects (vendor name,
//! product code, revision) and regular ones (product name, model name); stream access
//! by category (codes 1 to 3: basic, regular, extended, which adds nothing here) and
//! individual access (code 4). Conformity level 0x82.

use super::exception::Exception;

/// What the node says it is (function 43/14). Each object is sent as is; one longer
/// than 240 bytes is cut there (an object must fit one response).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Identification {
    /// Object 0, basic: the vendor's name.
    pub vendor_name: &'static str,
    /// Object 1, basic: the product code.
    pub product_code: &'static str,
    /// Object 2, basic: the revision, `major.minor[.patch]`.
    pub revision: &'static str,
    /// Object 4, regular: the product's name.
    pub product_name: &'static str,
    /// Object 5, regular: the model: the core and the scene (for example
    /// `f32 elliptic, demo scene R1 = R2 = 50 mm`). Empty: the estimator's type name.
    pub model_name: &'static str,
}

impl Default for Identification {
    fn default() -> Self {
        Identification {
            vendor_name: "misalign",
            product_code: "misalign-node",
            revision: env!("CARGO_PKG_VERSION"),
            product_name: "misalign condition monitor",
            model_name: "",
        }
    }
}

/// The longest object sent (bytes): one object always fits one response.
pub const OBJECT_MAX: usize = 240;

/// Basic and regular identification, stream and individual access.
const CONFORMITY: u8 = 0x82;

/// The MEI type of read device identification.
pub(crate) const MEI_DEVICE_ID: u8 = 0x0E;

/// The objects in id order, with the answer's model name.
fn objects<'a>(ident: &'a Identification, model_name: &'a str) -> [(u8, &'a str); 5] {
    [
        (0, ident.vendor_name),
        (1, ident.product_code),
        (2, ident.revision),
        (4, ident.product_name),
        (5, model_name),
    ]
}

/// Answers the request PDU `pdu` (function code first) into `out` (the response
/// PDU, function code first); the response's length.
pub(crate) fn read(
    ident: &Identification,
    model_name: &str,
    pdu: &[u8],
    out: &mut [u8],
) -> Result<usize, Exception> {
    let (Some(&mei), Some(&code), Some(&id)) = (pdu.get(1), pdu.get(2), pdu.get(3)) else {
        return Err(Exception::IllegalDataValue);
    };
    if mei != MEI_DEVICE_ID {
        return Err(Exception::IllegalFunction);
    }
    let objects = objects(ident, model_name);
    // The last object id of the category.
    let last = match code {
        1 => 2,
        2..=4 => u8::MAX,
        _ => return Err(Exception::IllegalDataValue),
    };
    let known = objects.iter().any(|&(i, _)| i == id);
    if code == 4 && !known {
        return Err(Exception::IllegalDataAddress);
    }
    // Stream access from an unknown object restarts at object 0.
    let first = if known && id <= last { id } else { 0 };
    let header = [0x2B, MEI_DEVICE_ID, code, CONFORMITY, 0, 0, 0];
    let head = out
        .get_mut(..header.len())
        .ok_or(Exception::ServerDeviceFailure)?;
    head.copy_from_slice(&header);
    let mut at = header.len();
    let mut count = 0u8;
    let (mut more, mut next) = (0u8, 0u8);
    for &(i, value) in objects.iter().filter(|&&(i, _)| i >= first && i <= last) {
        if code == 4 && i != id {
            continue;
        }
        let bytes = value.as_bytes();
        let bytes = bytes.get(..OBJECT_MAX).unwrap_or(bytes);
        let end = at + 2 + bytes.len();
        let Some(slot) = out.get_mut(at..end) else {
            (more, next) = (0xFF, i);
            break;
        };
        slot[0] = i;
        slot[1] = bytes.len() as u8;
        slot[2..].copy_from_slice(bytes);
        at = end;
        count = count.saturating_add(1);
    }
    if let Some(tail) = out.get_mut(4..7) {
        tail.copy_from_slice(&[more, next, count]);
    }
    Ok(at)
}
