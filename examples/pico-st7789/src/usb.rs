//! The Pico's USB serial port: a CDC ACM device (VID:PID 16c0:27dd, the
//! shared ID for CDC devices), made the same way by both firmwares, its
//! product string naming the firmware. The live firmware takes scenes on
//! it; the embedded-scene firmware answers with what it measured.
//!
//! Invariants: made once per firmware (its bus allocator is a static);
//! the device and port are the caller's to poll, from its USB interrupt.

use rp2040_hal::clocks::UsbClock;
use rp2040_hal::pac;
use rp2040_hal::usb::UsbBus;
use usb_device::class_prelude::UsbBusAllocator;
use usb_device::prelude::*;
use usbd_serial::SerialPort;

/// The USB device and its serial port.
pub type SerialDevice = (UsbDevice<'static, UsbBus>, SerialPort<'static, UsbBus>);

/// The serial device on the Pico's USB controller (`regs` and `dpram`,
/// from [`Peripherals`](octrace_pico::board::Peripherals)), its product
/// string `product`. Panics only if a firmware made it twice.
pub fn serial_device(
    regs: pac::USBCTRL_REGS,
    dpram: pac::USBCTRL_DPRAM,
    clock: UsbClock,
    resets: &mut pac::RESETS,
    product: &'static str,
) -> SerialDevice {
    let bus: &'static UsbBusAllocator<UsbBus> = cortex_m::singleton!(: UsbBusAllocator<UsbBus> =
        UsbBusAllocator::new(UsbBus::new(regs, dpram, clock, true, resets)))
    .unwrap();
    let serial = SerialPort::new(bus);
    let strings = StringDescriptors::default().manufacturer("octrace").product(product).serial_number("1");
    let device = UsbDeviceBuilder::new(bus, UsbVidPid(0x16c0, 0x27dd))
        .strings(&[strings])
        .unwrap()
        .max_packet_size_0(64)
        .unwrap()
        .device_class(usbd_serial::USB_CLASS_CDC)
        .build();
    (device, serial)
}
