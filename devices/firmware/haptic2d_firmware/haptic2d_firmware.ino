// haptic2d firmware for Haply M0 (SAMD21) and M3 (SAMD51) boards.
//
// SPDX-License-Identifier: MIT OR Apache-2.0
//
// The stock protocol (reset, setup, write) plus a watchdog, a reset that zeroes the motors, the
// torque clamp on the board and an identify query: docs/FIRMWARE.md. Everything but the serial
// port lives in src/ (the same C core the native build tests).

#include "src/h2df.h"
#include "src/h2df_hal.h"

#if defined(SERIAL_PORT_USBVIRTUAL)
#define H2DF_SERIAL SERIAL_PORT_USBVIRTUAL
#else
#define H2DF_SERIAL Serial
#endif

extern "C" int h2df_serial_available(void) { return H2DF_SERIAL.available(); }

extern "C" int h2df_serial_read(void) { return H2DF_SERIAL.read(); }

extern "C" void h2df_serial_write(const uint8_t *bytes, size_t n)
{
    H2DF_SERIAL.write(bytes, n);
}

static struct h2df fw;

void setup()
{
    // Motors first: every output zero before anything else can happen.
    h2df_init(&fw);
    H2DF_SERIAL.begin(115200); // USB CDC ignores the baud rate
}

void loop() { h2df_poll(&fw); }
