/* A stub of the few Arduino calls the haptic2d firmware uses, for the native Linux build
 * (implemented in arduino_stub.c). Not the Arduino API: just its names and meanings.
 *
 * SPDX-License-Identifier: MIT OR Apache-2.0 */
#ifndef H2DF_NATIVE_ARDUINO_H
#define H2DF_NATIVE_ARDUINO_H

#include <stdbool.h>
#include <stdint.h>

#ifdef __cplusplus
extern "C" {
#endif

#define LOW 0u
#define HIGH 1u
#define INPUT 0u
#define OUTPUT 1u
#define INPUT_PULLUP 2u
#define CHANGE 2u

void pinMode(uint32_t pin, uint32_t mode);
void digitalWrite(uint32_t pin, uint32_t value);
int digitalRead(uint32_t pin);
int analogRead(uint32_t pin);
void analogWrite(uint32_t pin, uint32_t value);
void analogWriteResolution(int bits);
unsigned long micros(void);
unsigned long millis(void);
void attachInterrupt(uint32_t pin, void (*callback)(void), uint32_t mode);
#define digitalPinToInterrupt(p) (p)
void noInterrupts(void);
void interrupts(void);

#ifdef __cplusplus
}
#endif

#endif
