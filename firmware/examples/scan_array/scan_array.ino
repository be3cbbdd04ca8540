/*
 * scan_array.ino - stream a row/column multiplexed analog tactile array to tactsense.
 *
 * The array: 8 row lines and 8 column lines; a taxel sits where a row crosses a column.
 * The sketch drives one row at a time and reads the 8 columns through an 8:1 analog
 * multiplexer (74HC4051: select lines S0..S2, common output to A0), one A/D reading
 * per taxel. Adapt ROW_PINS, MUX_SELECT_PINS, MUX_OUTPUT and read_taxel() to your
 * wiring (a resistive array may need a pull-down on the mux output; a capacitive one
 * a charge-and-measure step in place of analogRead).
 *
 * The protocol (docs/protocol.md) is handled by the tactsense library (firmware/):
 * the host sends IDENTIFY (answered with the sensor description), START and STOP;
 * while streaming, one FRAME per scan period, each with its sequence number and the
 * scan's start on the device clock. A scan that cannot be made on time is dropped
 * with ts_drop_frame, so the host counts it as lost instead of never knowing.
 *
 * Install: copy the folder firmware/ into your Arduino libraries folder as
 * "tactsense" (or copy tactsense.h and tactsense.c next to this sketch and write
 * #include "tactsense.h"). Boards with native USB (Leonardo, Micro, Zero, Due,
 * Teensy, RP2040, ESP32-S2/S3) ignore the baud rate; on a board with a USB-UART
 * bridge use a rate the host opens the port at (tactsense: 921600). An AVR Uno has
 * too little RAM for the sensor description as a string; see ts_ident_text to send
 * it from flash in pieces.
 *
 * Host: tactsense record /dev/ttyACM0 --out run.h5   (or live, or view)
 */
#include <tactsense.h>

/* ---- the array ----------------------------------------------------------------- */

const uint8_t ROWS = 8;
const uint8_t COLS = 8;
const uint8_t ROW_PINS[ROWS] = {2, 3, 4, 5, 6, 7, 8, 9}; /* row 0 = under the fingertip */
const uint8_t MUX_SELECT_PINS[3] = {10, 11, 12};         /* 74HC4051 S0, S1, S2 */
const uint8_t MUX_OUTPUT = A0;
const unsigned SETTLE_US = 20; /* after switching the mux, before reading [us] */

/* One scan every 10 ms (100 Hz). It must equal 1 / scan_rate_hz of SENSOR_TOML: the
   host uses it to count the frames lost in a gap longer than 65,535 frames. */
const uint32_t SCAN_PERIOD_US = 10000UL;

/* The sensor description the host reads from IDENT. Start from
   `tactsense sensor show --out my_array.toml`, describe your array (rows, cols,
   spacing, A/D converter, scan rate) and paste it here, one line per string. */
static const char SENSOR_TOML[] =
    "extends = \"initial\"\n"
    "name = \"scan_array\"\n"
    "description = \"8 x 8 row/column multiplexed array, scan_array.ino\"\n"
    "[electronics]\n"
    "adc_bits = 10\n"
    "nominal_counts = 500.0\n"
    "scan_rate_hz = 100.0\n";

/* ---- the stream ---------------------------------------------------------------- */

static ts_context ts;
static uint16_t counts[ROWS * COLS]; /* row-major: counts[row * COLS + col] */
static bool streaming = false;
static uint32_t next_scan_us; /* micros() at which the next scan is due */

/* The library hands over the encoded bytes of each packet in pieces. */
static void write_serial(void *user, const uint8_t *data, size_t len)
{
    (void)user;
    Serial.write(data, len);
}

static uint16_t read_taxel(uint8_t col)
{
    for (uint8_t s = 0; s < 3; s++) digitalWrite(MUX_SELECT_PINS[s], (col >> s) & 1 ? HIGH : LOW);
    delayMicroseconds(SETTLE_US);
    return (uint16_t)analogRead(MUX_OUTPUT); /* 0..1023 on a 10-bit converter */
}

static void scan(uint16_t *out)
{
    for (uint8_t r = 0; r < ROWS; r++) {
        pinMode(ROW_PINS[r], OUTPUT); /* drive this row; the others float */
        digitalWrite(ROW_PINS[r], HIGH);
        for (uint8_t c = 0; c < COLS; c++) out[r * COLS + c] = read_taxel(c);
        digitalWrite(ROW_PINS[r], LOW);
        pinMode(ROW_PINS[r], INPUT);
    }
}

void setup()
{
    for (uint8_t r = 0; r < ROWS; r++) pinMode(ROW_PINS[r], INPUT);
    for (uint8_t s = 0; s < 3; s++) pinMode(MUX_SELECT_PINS[s], OUTPUT);
    Serial.begin(921600);
    ts_init(&ts, ROWS, COLS, SCAN_PERIOD_US * 1000UL, write_serial, NULL);
}

void loop()
{
    /* the host's commands */
    while (Serial.available() > 0) {
        switch (ts_receive(&ts, (uint8_t)Serial.read())) {
        case TS_IDENTIFY:
            ts_send_ident(&ts, "scan_array", "1.0.0", "0001", SENSOR_TOML);
            break;
        case TS_START:
            if (!streaming) next_scan_us = micros();
            streaming = true;
            break;
        case TS_STOP:
            if (streaming) ts_send_end(&ts); /* the last sequence number and the frame count */
            streaming = false;
            break;
        }
    }
    if (!streaming) return;

    uint32_t now = micros();
    if ((int32_t)(now - next_scan_us) < 0) return; /* not due yet */
    /* Scans whose time passed while the line was busy are dropped, not sent late: each
       consumes its sequence number and its scan period, so the host counts it. */
    while (now - next_scan_us >= SCAN_PERIOD_US) {
        ts_drop_frame(&ts);
        next_scan_us += SCAN_PERIOD_US;
    }
    /* The device clock: one scan period per scan since power-up (ts_scan_time_us). A
       free-running clock works too: ts_clock_us(&ts, micros()) at the scan's start. */
    uint64_t scan_start_us = ts_scan_time_us(&ts);
    scan(counts);
    ts_send_frame(&ts, scan_start_us, counts);
    next_scan_us += SCAN_PERIOD_US;
}
