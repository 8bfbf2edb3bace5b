//! The world link's period allocates nothing once the session is open (DESIGN §1.3): sealing a
//! port message, sending it and polling the socket (MAC checks, decoding, keeping the newest). The
//! shared counting allocator counts per thread, so the world end's thread allocates freely.

use std::net::UdpSocket;
use std::sync::atomic::AtomicBool;
use std::time::Duration;

use haptic2d_devices::udp::UdpKey;
use haptic2d_devices::world_link::{
    LinkEndpoint, PortMessage, KIND_TO_DEVICE, KIND_TO_WORLD, PORT_LEN,
};

use haptic2d_test_support::alloc::allocations;

#[test]
fn a_period_of_the_world_link_allocates_nothing_once_open() {
    let key = UdpKey::from_bytes(&[0x42; 32]).unwrap();
    let sock = UdpSocket::bind("127.0.0.1:0").unwrap();
    let addr = sock.local_addr().unwrap().to_string();
    let k2 = key.clone();
    // The world end echoes every port message back as a world → device message.
    let world = std::thread::spawn(move || {
        let mut w =
            LinkEndpoint::accept(sock, &k2, Duration::from_secs(5), &AtomicBool::new(false))
                .unwrap();
        let mut b = [0u8; PORT_LEN];
        let mut seq = 0;
        let t0 = std::time::Instant::now();
        while t0.elapsed() < Duration::from_secs(5) {
            if let Some(m) = w.poll(KIND_TO_WORLD) {
                seq += 1;
                PortMessage { seq, ..m }.seal(&k2, KIND_TO_DEVICE, w.session(), &mut b);
                w.send(&b);
                if m.flags != 0 {
                    break;
                }
            }
            std::thread::sleep(Duration::from_micros(200));
        }
    });
    let mut dev = LinkEndpoint::connect(&addr, &key, Duration::from_secs(5)).unwrap();
    let mut b = [0u8; PORT_LEN];
    let mut period = |seq: u32, flags: u32| {
        let m = PortMessage {
            seq,
            flags,
            pose: [seq as f64 * 1e-3, 0.0, 0.0],
            ..PortMessage::default()
        };
        m.seal(&key, KIND_TO_WORLD, dev.session(), &mut b);
        dev.send(&b);
        std::thread::sleep(Duration::from_millis(1));
        dev.poll(KIND_TO_DEVICE)
    };
    for seq in 1..20 {
        period(seq, 0);
    }
    let before = allocations();
    let mut got = 0;
    for seq in 20..520 {
        got += period(seq, 0).is_some() as u32;
    }
    let allocated = allocations() - before;
    period(520, 1);
    world.join().unwrap();
    assert!(got > 100, "only {got} answers came back");
    assert_eq!(allocated, 0);
}
