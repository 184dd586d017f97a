//! The node's side in the page: a Modbus node in the page itself
//! ([`PageNode`]: `misalign::modbus::Server` over the monitor, as the firmware runs it)
//! that the Plan view commissions to check a configuration as a node would (its
//! `commit_error` and all), and that the Node view offers as a node to try the console
//! on; and the library's decoding of what any node answers (an event slot as the
//! monitor example's `--events` row, a `commit_error` as its reason).

use misalign::float::Auto;
use misalign::modbus::{Identification, Server, ServerConfig, event_from_registers, reason};
use misalign::monitor::scenario::{self, Scenario};
use misalign::monitor::{Config, ConfigError, Monitor};
use misalign::prepared::PreparedError;
use misalign_cli::monitor_output::event_row;
use misalign_cli::replay::Model;
use wasm_bindgen::prelude::*;

/// The page's node: the f32 core on the built-in scenario's scene, the default
/// configuration, scenes taken over the bus; with `samples`, the built-in scenario
/// monitored first (as `cargo xtask modbus --serve` does), so that it holds events.
#[wasm_bindgen]
pub struct PageNode {
    server: Server<Auto>,
}

#[wasm_bindgen]
impl PageNode {
    #[wasm_bindgen(constructor)]
    pub fn new(samples: bool) -> Result<PageNode, JsError> {
        PageNode::start(samples).map_err(|e| JsError::new(&e))
    }

    /// One RTU frame in, the node's answer out (empty: none, as for a wrong CRC or
    /// another unit).
    pub fn request(&mut self, frame: &[u8]) -> Vec<u8> {
        for &b in frame {
            self.server.receive(b);
        }
        if self.server.response().is_none() {
            // The line's silence: a function the server does not know is answered now.
            self.server.idle();
        }
        let answer = self
            .server
            .response()
            .map(<[u8]>::to_vec)
            .unwrap_or_default();
        self.server.sent();
        answer
    }

    /// The node's millisecond clock (the unlock's timeout).
    pub fn tick(&mut self, now_ms: u32) {
        self.server.tick(now_ms);
    }

    /// The planner's table (the `--thresholds` file) for `scene` on `model` over loads
    /// up to `load_max` (N), under the configuration this node runs (what was
    /// committed to it).
    pub fn thresholds(
        &self,
        scene: Option<String>,
        model: &str,
        load_max: f64,
    ) -> Result<String, JsError> {
        let model = Model::parse(model).map_err(|e| JsError::new(&e))?;
        crate::plan_text(scene.as_deref(), model, load_max, self.config())
            .map_err(|e| JsError::new(&e))
    }
}

impl PageNode {
    /// The node, or why not.
    pub fn start(samples: bool) -> Result<PageNode, String> {
        let core = scenario::estimator::<Auto>().map_err(|e| e.to_string())?;
        let monitor = Monitor::new(core, Config::default()).map_err(|e| e.to_string())?;
        let config = ServerConfig {
            ident: Identification {
                model_name: "f32 core (float::Auto), the built-in scenario's scene, in the page",
                ..Identification::default()
            },
            ..ServerConfig::default()
        };
        let mut server = Server::new(monitor, config).map_err(|e| e.to_string())?;
        server.accept_scenes();
        if samples {
            for sample in Scenario::new() {
                server.process(sample);
            }
        }
        Ok(PageNode { server })
    }

    /// The configuration the node runs.
    pub fn config(&self) -> &Config {
        self.server.monitor().config()
    }
}

/// `eventRow(registers)`: one event slot's registers (`event_<i>_seq` first) as the
/// monitor example's `--events` row (the monitor's own event, decoded by
/// `misalign::modbus::event_from_registers`); empty for an empty slot.
#[wasm_bindgen(js_name = eventRow)]
pub fn event_row_of(registers: &[u16]) -> Result<String, JsError> {
    event_from_registers(registers)
        .map(|e| e.map(|e| event_row(&e)).unwrap_or_default())
        .map_err(|e| JsError::new(&format!("event slot: {e}")))
}

/// `commitReason(code)`: the register `commit_error`'s code in words (the library's
/// own messages for the configuration's and the scene's errors).
#[wasm_bindgen(js_name = commitReason)]
pub fn commit_reason(code: u16) -> String {
    use ConfigError as C;
    use PreparedError as P;
    let config = [
        C::Threshold,
        C::WarningAboveAlarm,
        C::Deadband,
        C::Stop,
        C::NominalSpeed,
        C::Range,
        C::SpikeWindow,
        C::Smoothing,
        C::Trend,
        C::Friction,
    ];
    let scene = [
        P::Length,
        P::Magic,
        P::Kind,
        P::Version,
        P::Checksum,
        P::Value,
    ];
    match code {
        reason::NONE => "applied".into(),
        reason::NOTHING_STAGED => "nothing staged".into(),
        _ => config
            .into_iter()
            .find(|&e| reason::config(e) == code)
            .map(|e| format!("the configuration: {e}"))
            .or_else(|| {
                scene
                    .into_iter()
                    .find(|&e| reason::scene(e) == code)
                    .map(|e| e.to_string())
            })
            .unwrap_or_else(|| format!("reason {code:#x}")),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use ConfigError as C;
    use misalign::modbus::crc16;

    /// `frame` with its unit and CRC.
    fn frame(pdu: &[u8]) -> Vec<u8> {
        let mut f = vec![1];
        f.extend_from_slice(pdu);
        let crc = crc16(&f);
        f.extend_from_slice(&crc.to_le_bytes());
        f
    }

    /// A configuration that the node refuses is refused in the page with the node's
    /// reason, and one it takes is the one the planner then plans with.
    #[test]
    fn the_page_node_commits_as_a_node() {
        let mut node = PageNode::start(false).unwrap();
        let code = misalign::modbus::DEFAULT_UNLOCK_CODE.to_be_bytes();
        let answer = node.request(&frame(&[6, 0, 9, code[0], code[1]]));
        assert_eq!(answer[1], 6, "{answer:02x?}");
        // config_warning (25) = 2.0 > the alarm: refused at the commit.
        let [a, b, c, d] = 2.0f32.to_bits().to_be_bytes();
        let answer = node.request(&frame(&[16, 0, 25, 0, 2, 4, a, b, c, d]));
        assert_eq!(answer[1], 16, "{answer:02x?}");
        let answer = node.request(&frame(&[6, 0, 10, 0, 1]));
        assert_eq!(answer[1..3], [0x86, 3], "{answer:02x?}");
        let answer = node.request(&frame(&[3, 0, 11, 0, 1]));
        let why = u16::from_be_bytes([answer[3], answer[4]]);
        assert_eq!(
            commit_reason(why),
            format!("the configuration: {}", C::WarningAboveAlarm)
        );
        // 0.5, below the alarm: committed, and run.
        let [a, b, c, d] = 0.5f32.to_bits().to_be_bytes();
        node.request(&frame(&[16, 0, 25, 0, 2, 4, a, b, c, d]));
        let answer = node.request(&frame(&[6, 0, 10, 0, 1]));
        assert_eq!(answer[1], 6, "{answer:02x?}");
        let misalign::monitor::Thresholds::SlipRatio { warning, .. } = node.config().thresholds
        else {
            panic!("thresholds on d/b");
        };
        assert_eq!(warning, 0.5);
        // A wrong CRC: no answer.
        let mut bad = frame(&[3, 0, 11, 0, 1]);
        bad[6] ^= 1;
        assert!(node.request(&bad).is_empty());
    }
}
