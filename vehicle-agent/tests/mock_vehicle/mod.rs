//! A mock MAVLink vehicle on loopback UDP, written with the `mavlink` crate: it answers the
//! mission and command protocols as a test chooses ([`Behaviour`]: dropping messages so the
//! link's retries must work, refusing, or silent), records what it received ([`Board`]) and
//! streams the position and reached item the test sets.

use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::{Arc, Mutex, PoisonError};
use std::thread::JoinHandle;
use std::time::{Duration, Instant};

use mavlink::dialects::common::{self as mav, MavCmd, MavMessage as M};
use mavlink::{Connectable, MavConnection, MavHeader, UdpConfig, UdpMode};
use std::net::UdpSocket;

/// The mock's own header: system 1, component 1.
pub const VEHICLE: MavHeader = MavHeader {
    system_id: 1,
    component_id: 1,
    sequence: 0,
};

/// How the mock vehicle misbehaves.
#[derive(Clone, Copy, PartialEq)]
pub enum Behaviour {
    /// Ignores the first MISSION_COUNT and the first copy of item 2, answers everything else.
    Lossy,
    /// Answers MISSION_COUNT with MISSION_ACK MAV_MISSION_ERROR.
    Refuses,
    /// Never answers.
    Silent,
}

/// What the mock received, and what it streams (set by the test).
#[derive(Default)]
pub struct Board {
    /// MISSION_COUNTs received.
    pub counts: usize,
    /// The mission items taken, in order.
    pub items: Vec<mav::MISSION_ITEM_INT_DATA>,
    /// The COMMAND_LONGs received.
    pub commands: Vec<MavCmd>,
    /// The position it streams.
    pub position: Option<mav::GLOBAL_POSITION_INT_DATA>,
    /// The reached item it streams.
    pub reached: Option<u16>,
}

/// A vehicle on loopback UDP (`udpin`), answering the mission and command protocols.
pub struct Mock {
    /// Its UDP port on loopback.
    pub port: u16,
    board: Arc<Mutex<Board>>,
    stop: Arc<AtomicBool>,
    thread: Option<JoinHandle<Result<(), String>>>,
}

impl Mock {
    pub fn start(behaviour: Behaviour) -> Result<Mock, Box<dyn std::error::Error>> {
        let socket = UdpSocket::bind("127.0.0.1:0")?;
        let port = socket.local_addr()?.port();
        let conn = UdpConfig::from_socket(socket, UdpMode::Udpin)?
            .read_timeout(Duration::from_millis(10))
            .connect::<M>()?;
        let (board, stop) = (
            Arc::new(Mutex::new(Board::default())),
            Arc::new(AtomicBool::new(false)),
        );
        let (b, s) = (Arc::clone(&board), Arc::clone(&stop));
        let thread = std::thread::spawn(move || serve(&conn, behaviour, &b, &s));
        Ok(Mock {
            port,
            board,
            stop,
            thread: Some(thread),
        })
    }

    pub fn board(&self) -> std::sync::MutexGuard<'_, Board> {
        self.board.lock().unwrap_or_else(PoisonError::into_inner)
    }
}

impl Drop for Mock {
    fn drop(&mut self) {
        self.stop.store(true, Ordering::Relaxed);
        if let Some(Ok(Err(e))) = self.thread.take().map(JoinHandle::join) {
            if !std::thread::panicking() {
                panic!("the mock vehicle failed: {e}");
            }
        }
    }
}

/// The mock's loop: answers, and streams the board's position and reached item every 50 ms.
fn serve(
    conn: &mavlink::Connection<M>,
    behaviour: Behaviour,
    board: &Mutex<Board>,
    stop: &AtomicBool,
) -> Result<(), String> {
    let send = |m: M| conn.send(&VEHICLE, &m).map(drop).map_err(|e| e.to_string());
    let (mut count, mut next, mut dropped_item) = (0u16, 0u16, false);
    let mut streamed = Instant::now();
    while !stop.load(Ordering::Relaxed) {
        if streamed.elapsed() > Duration::from_millis(50) {
            streamed = Instant::now();
            let (position, reached) = {
                let b = board.lock().unwrap_or_else(PoisonError::into_inner);
                (b.position.clone(), b.reached)
            };
            if let Some(p) = position {
                send(M::GLOBAL_POSITION_INT(p))?;
            }
            if let Some(seq) = reached {
                send(M::MISSION_ITEM_REACHED(mav::MISSION_ITEM_REACHED_DATA {
                    seq,
                }))?;
            }
        }
        let Ok((_, msg)) = conn.recv() else { continue };
        let mut b = board.lock().unwrap_or_else(PoisonError::into_inner);
        let request = |seq| {
            let mut r = mav::MISSION_REQUEST_INT_DATA::default();
            (r.seq, r.target_system, r.target_component) = (seq, 255, 190);
            M::MISSION_REQUEST_INT(r)
        };
        let ack = |result| {
            let mut a = mav::MISSION_ACK_DATA::default();
            (a.mavtype, a.target_system, a.target_component) = (result, 255, 190);
            M::MISSION_ACK(a)
        };
        match msg {
            M::MISSION_COUNT(c) => {
                b.counts += 1;
                match behaviour {
                    Behaviour::Silent => {}
                    Behaviour::Lossy if b.counts == 1 => {} // as if our request were lost
                    Behaviour::Refuses => send(ack(mav::MavMissionResult::MAV_MISSION_ERROR))?,
                    Behaviour::Lossy => {
                        (count, next) = (c.count, 0);
                        b.items.clear();
                        send(request(0))?;
                    }
                }
            }
            M::MISSION_ITEM_INT(item) if behaviour == Behaviour::Lossy => {
                if item.seq == 2 && !dropped_item {
                    dropped_item = true; // lost on the way: the link must send it again
                    continue;
                }
                if item.seq == next {
                    b.items.push(item);
                    next += 1;
                }
                send(if next < count {
                    request(next)
                } else {
                    ack(mav::MavMissionResult::MAV_MISSION_ACCEPTED)
                })?;
            }
            M::COMMAND_LONG(c) if behaviour != Behaviour::Silent => {
                b.commands.push(c.command);
                let mut a = mav::COMMAND_ACK_DATA::default();
                (a.command, a.result) = (c.command, mav::MavResult::MAV_RESULT_ACCEPTED);
                send(M::COMMAND_ACK(a))?;
            }
            _ => {}
        }
    }
    Ok(())
}
