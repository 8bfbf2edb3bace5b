//! Serial ports: opening a board's port, pseudo-terminal pairs for the emulator, and listing the
//! ports with their USB ids (read from sysfs on Linux, since `serialport` is built without libudev).

use std::path::Path;
use std::time::Duration;

use serialport::{SerialPort, TTYPort};

/// The stream read timeout the driver and the emulator use: short, so that the transport's own
/// deadline decides (µs granularity is not needed: replies arrive within a period).
pub const STREAM_TIMEOUT: Duration = Duration::from_micros(500);

/// A board's serial port whose reads do not allocate: `serialport`'s read builds a boxed
/// `io::Error` for every read timeout, which the driver's exchange would hit under load (caught by
/// `tests/it/haply_no_alloc.rs`). Reads wait with `ppoll` for at most [`STREAM_TIMEOUT`] and return
/// `Ok(0)` when nothing came; errors are OS errors (no allocation). Writes go through `serialport`.
#[derive(Debug)]
pub struct BoardPort {
    tty: TTYPort,
}

impl BoardPort {
    /// The underlying port.
    pub fn tty(&self) -> &TTYPort {
        &self.tty
    }
}

impl std::io::Read for BoardPort {
    fn read(&mut self, buf: &mut [u8]) -> std::io::Result<usize> {
        use std::os::unix::io::AsRawFd;
        if buf.is_empty() {
            return Ok(0);
        }
        let fd = self.tty.as_raw_fd();
        let mut pfd = libc::pollfd {
            fd,
            events: libc::POLLIN,
            revents: 0,
        };
        let ts = libc::timespec {
            tv_sec: 0,
            tv_nsec: STREAM_TIMEOUT.as_nanos() as libc::c_long,
        };
        // SAFETY: `pfd` and `ts` are valid for the call; one descriptor, no signal mask.
        let r = unsafe { libc::ppoll(&mut pfd, 1, &ts, std::ptr::null()) };
        if r < 0 {
            return Err(std::io::Error::last_os_error());
        }
        if r == 0 {
            return Ok(0);
        }
        if pfd.revents & (libc::POLLHUP | libc::POLLERR | libc::POLLNVAL) != 0
            && pfd.revents & libc::POLLIN == 0
        {
            return Err(std::io::Error::from_raw_os_error(libc::EIO));
        }
        // SAFETY: `buf` is valid for `buf.len()` bytes; `fd` is open (owned by `self.tty`).
        let n = unsafe { libc::read(fd, buf.as_mut_ptr().cast(), buf.len()) };
        if n < 0 {
            return Err(std::io::Error::last_os_error());
        }
        Ok(n as usize)
    }
}

impl std::io::Write for BoardPort {
    fn write(&mut self, buf: &[u8]) -> std::io::Result<usize> {
        self.tty.write(buf)
    }
    fn flush(&mut self) -> std::io::Result<()> {
        self.tty.flush()
    }
}

/// Opens the serial port at `path` for a board (the baud rate is ignored by USB CDC ACM), raw mode.
pub fn open_port(path: &str) -> Result<BoardPort, String> {
    let builder = serialport::new(path, 115_200).timeout(STREAM_TIMEOUT);
    let mut port = TTYPort::open(&builder).map_err(|e| {
        format!(
            "cannot open the serial port {path}: {e}\n    check: the path (see `haptic2d devices`), that you may use it (Linux: the `dialout` group), and that no other program has it open"
        )
    })?;
    make_raw(&port).map_err(|e| format!("{path}: {e}"))?;
    let _ = port.set_exclusive(false);
    Ok(BoardPort { tty: port })
}

/// Puts a tty in raw mode (no echo, no line editing, no CR/LF translation): the protocol is binary.
pub fn make_raw(port: &TTYPort) -> Result<(), String> {
    use std::os::unix::io::AsRawFd;
    let fd = port.as_raw_fd();
    // SAFETY: `fd` is an open tty owned by `port`; the termios struct is fully initialised by
    // tcgetattr before use.
    unsafe {
        let mut t: libc::termios = std::mem::zeroed();
        if libc::tcgetattr(fd, &mut t) != 0 {
            return Err(format!(
                "cannot read the terminal settings: {}",
                std::io::Error::last_os_error()
            ));
        }
        libc::cfmakeraw(&mut t);
        t.c_cc[libc::VMIN] = 0;
        t.c_cc[libc::VTIME] = 0;
        if libc::tcsetattr(fd, libc::TCSANOW, &t) != 0 {
            return Err(format!(
                "cannot set raw mode: {}",
                std::io::Error::last_os_error()
            ));
        }
    }
    Ok(())
}

/// A pseudo-terminal pair for an emulated board: the emulator serves `master`; a host opens
/// `path` (the slave side) like a serial port. The slave side is kept open through a plain file
/// (without the advisory lock `serialport` takes, so that a host can still open it), so the master
/// never sees a hang-up while no host is connected.
pub struct Pty {
    /// The emulator's end.
    pub master: TTYPort,
    /// The slave end, held open (no lock).
    pub keep: std::fs::File,
    /// Path of the slave device (e.g. `/dev/pts/5`).
    pub path: String,
}

impl Pty {
    /// A new pair in raw mode with short read timeouts.
    pub fn new() -> Result<Self, String> {
        let (mut master, slave) =
            TTYPort::pair().map_err(|e| format!("cannot create a pseudo-terminal pair: {e}"))?;
        let path = slave
            .name()
            .ok_or("the pseudo-terminal has no name")?
            .to_string();
        make_raw(&slave)?;
        let keep = std::fs::OpenOptions::new()
            .read(true)
            .write(true)
            .open(&path)
            .map_err(|e| format!("cannot open the pseudo-terminal {path}: {e}"))?;
        // Dropping the serialport handle releases its lock; `keep` holds the tty open.
        drop(slave);
        master
            .set_timeout(STREAM_TIMEOUT)
            .map_err(|e| e.to_string())?;
        Ok(Self { master, keep, path })
    }
}

/// A serial port found on this machine.
#[derive(Clone, Debug, PartialEq)]
pub struct PortInfo {
    /// Device path.
    pub path: String,
    /// USB vendor and product id, when the port is a USB device and they could be read.
    pub usb: Option<(u16, u16)>,
    /// USB product string or port type, for display.
    pub description: String,
}

/// The serial ports of this machine with their USB ids. Without libudev `serialport` may not know
/// the ids, so they are read from `/sys/class/tty/NAME/device/../idVendor` (Linux) as well.
pub fn list_ports() -> Result<Vec<PortInfo>, String> {
    let ports =
        serialport::available_ports().map_err(|e| format!("cannot list serial ports: {e}"))?;
    let mut out = Vec::new();
    for p in ports {
        let (mut usb, mut description) = match &p.port_type {
            serialport::SerialPortType::UsbPort(u) => (
                Some((u.vid, u.pid)),
                u.product.clone().unwrap_or_else(|| "USB serial".into()),
            ),
            serialport::SerialPortType::PciPort => (None, "PCI".into()),
            serialport::SerialPortType::BluetoothPort => (None, "Bluetooth".into()),
            serialport::SerialPortType::Unknown => (None, "unknown".into()),
        };
        if usb.is_none() {
            if let Some((ids, product)) = sysfs_usb(&p.port_name) {
                usb = Some(ids);
                description = product.unwrap_or_else(|| "USB serial".into());
            }
        }
        out.push(PortInfo {
            path: p.port_name,
            usb,
            description,
        });
    }
    out.sort_by(|a, b| a.path.cmp(&b.path));
    Ok(out)
}

/// USB ids of tty `path` from sysfs: the interface's parent device holds `idVendor`/`idProduct`.
fn sysfs_usb(path: &str) -> Option<((u16, u16), Option<String>)> {
    let name = Path::new(path).file_name()?.to_str()?;
    let dev = Path::new("/sys/class/tty").join(name).join("device");
    for up in ["..", "../.."] {
        let d = dev.join(up);
        let read = |f: &str| std::fs::read_to_string(d.join(f)).ok();
        if let (Some(v), Some(p)) = (read("idVendor"), read("idProduct")) {
            let v = u16::from_str_radix(v.trim(), 16).ok()?;
            let p = u16::from_str_radix(p.trim(), 16).ok()?;
            return Some(((v, p), read("product").map(|s| s.trim().to_string())));
        }
    }
    None
}

/// The first port whose USB ids are in `ids`, or an error listing the ports found.
pub fn find_board(ids: &[(u16, u16)]) -> Result<String, String> {
    let ports = list_ports()?;
    if let Some(p) = ports
        .iter()
        .find(|p| p.usb.is_some_and(|u| ids.contains(&u)))
    {
        return Ok(p.path.clone());
    }
    let listed = if ports.is_empty() {
        "none".to_string()
    } else {
        ports
            .iter()
            .map(|p| match p.usb {
                Some((v, d)) => format!("{} ({v:04x}:{d:04x} {})", p.path, p.description),
                None => format!("{} ({})", p.path, p.description),
            })
            .collect::<Vec<_>>()
            .join(", ")
    };
    let want = ids
        .iter()
        .map(|(v, p)| format!("{v:04x}:{p:04x}"))
        .collect::<Vec<_>>()
        .join(", ");
    Err(format!(
        "haply:auto: no serial port with the USB ids of a Haply board ({want}); ports found: {listed}\n    fix: plug the board in, give its port with --device haply:PATH, or add its ids to board.usb_ids in the device file"
    ))
}
