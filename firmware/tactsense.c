/*
 * tactsense.c - the tactsense wire protocol, version 1, for the device side.
 * See tactsense.h for the API and docs/protocol.md for the protocol.
 */
#include "tactsense.h"

/* CRC-32/ISO-HDLC, reflected polynomial 0xEDB88320, four bits at a time: a table
   of 16 words (64 bytes) instead of 256 (1 KB). */
static const uint32_t ts_crc_nibble[16] = {
    0x00000000UL, 0x1db71064UL, 0x3b6e20c8UL, 0x26d930acUL, 0x76dc4190UL, 0x6b6b51f4UL,
    0x4db26158UL, 0x5005713cUL, 0xedb88320UL, 0xf00f9344UL, 0xd6d6a3e8UL, 0xcb61b38cUL,
    0x9b64c2b0UL, 0x86d3d2d4UL, 0xa00ae278UL, 0xbdbdf21cUL};

static uint32_t crc_step(uint32_t crc, uint8_t byte)
{
    crc ^= byte;
    crc = (crc >> 4) ^ ts_crc_nibble[crc & 15u];
    return (crc >> 4) ^ ts_crc_nibble[crc & 15u];
}

uint32_t ts_crc32(uint32_t crc, const uint8_t *data, size_t len)
{
    crc ^= 0xFFFFFFFFUL;
    while (len--) crc = crc_step(crc, *data++);
    return crc ^ 0xFFFFFFFFUL;
}

/* ---- COBS, one byte at a time ------------------------------------------------
   A block is a code byte n (1..255) and n - 1 data bytes; a block with n < 255
   stands for its data and one zero byte, the last block for its data alone. The
   block being filled starts at enc->code; in stream mode every finished block
   goes to the write callback and the buffer starts over. */

static void cobs_open(ts_encoder *e)
{
    if (e->len >= e->cap) {
        e->overflow = 1;
        return;
    }
    e->code = e->len++;
}

static void cobs_close(ts_encoder *e)
{
    if (e->overflow) return;
    e->buf[e->code] = (uint8_t)(e->len - e->code);
    if (e->write) {
        e->write(e->user, e->buf, e->len);
        e->total += e->len;
        e->len = 0;
    }
    cobs_open(e);
}

static void cobs_byte(ts_encoder *e, uint8_t b)
{
    if (e->overflow) return;
    if (e->len - e->code == 255) cobs_close(e); /* full block of 254: code 0xFF */
    if (b == 0) {
        cobs_close(e);
    } else if (e->len >= e->cap) {
        e->overflow = 1;
    } else {
        e->buf[e->len++] = b;
    }
}

static void put(ts_encoder *e, uint8_t b)
{
    e->crc = crc_step(e->crc, b);
    cobs_byte(e, b);
}

static void put_u16(ts_encoder *e, uint16_t v)
{
    put(e, (uint8_t)(v & 0xFFu));
    put(e, (uint8_t)(v >> 8));
}

static void put_u32(ts_encoder *e, uint32_t v)
{
    put_u16(e, (uint16_t)(v & 0xFFFFu));
    put_u16(e, (uint16_t)(v >> 16));
}

static void put_u64(ts_encoder *e, uint64_t v)
{
    put_u32(e, (uint32_t)(v & 0xFFFFFFFFUL));
    put_u32(e, (uint32_t)(v >> 32));
}

static void enc_begin(ts_encoder *e, uint8_t *buf, size_t cap, ts_write_fn write, void *user,
                      uint8_t kind)
{
    e->buf = buf;
    e->cap = cap;
    e->len = 0;
    e->code = 0;
    e->total = 0;
    e->crc = 0xFFFFFFFFUL;
    e->write = write;
    e->user = user;
    e->overflow = 0;
    cobs_open(e);
    put(e, TS_PROTOCOL_VERSION);
    put(e, kind);
}

/* Append the CRC, close the last block, add the delimiter; the bytes written, or
   0 if they did not fit. */
static size_t enc_end(ts_encoder *e)
{
    uint32_t crc = e->crc ^ 0xFFFFFFFFUL;
    int i;
    for (i = 0; i < 4; i++) cobs_byte(e, (uint8_t)((crc >> (8 * i)) & 0xFFu));
    if (e->overflow) return 0;
    e->buf[e->code] = (uint8_t)(e->len - e->code);
    if (e->len >= e->cap) return 0;
    e->buf[e->len++] = 0;
    if (e->write) {
        e->write(e->user, e->buf, e->len);
        e->total += e->len;
        return e->total;
    }
    return e->len;
}

static void enc_frame(ts_encoder *e, uint16_t sequence, uint64_t time_us, uint8_t rows,
                      uint8_t cols, const uint16_t *counts)
{
    size_t i, n = (size_t)rows * cols;
    put_u16(e, sequence);
    put_u64(e, time_us);
    put(e, rows);
    put(e, cols);
    for (i = 0; i < n; i++) put_u16(e, counts[i]);
}

size_t ts_encode_frame(uint8_t *out, size_t cap, uint16_t sequence, uint64_t device_time_us,
                       uint8_t rows, uint8_t cols, const uint16_t *counts)
{
    ts_encoder e;
    if (rows == 0 || cols == 0 || counts == NULL) return 0;
    enc_begin(&e, out, cap, NULL, NULL, TS_FRAME);
    enc_frame(&e, sequence, device_time_us, rows, cols, counts);
    return enc_end(&e);
}

size_t ts_encode_end(uint8_t *out, size_t cap, uint16_t last_sequence, uint32_t frames)
{
    ts_encoder e;
    enc_begin(&e, out, cap, NULL, NULL, TS_END);
    put_u16(&e, last_sequence);
    put_u32(&e, frames);
    return enc_end(&e);
}

size_t ts_encode_packet(uint8_t *out, size_t cap, uint8_t kind, const uint8_t *body,
                        size_t body_len)
{
    ts_encoder e;
    size_t i;
    enc_begin(&e, out, cap, NULL, NULL, kind);
    for (i = 0; i < body_len; i++) put(&e, body[i]);
    return enc_end(&e);
}

/* ---- the device context ------------------------------------------------------ */

void ts_init(ts_context *ts, uint8_t rows, uint8_t cols, uint32_t scan_period_ns,
             ts_write_fn write, void *user)
{
    ts->rows = rows;
    ts->cols = cols;
    ts->scan_period_ns = scan_period_ns;
    ts->sequence = 0;
    ts->frames = 0;
    ts->scans = 0;
    ts->clock_us = 0;
    ts->clock_last = 0;
    ts->enc.write = write;
    ts->enc.user = user;
    ts->rx_len = 0;
    ts->rx_skip = 0;
}

uint64_t ts_scan_time_us(const ts_context *ts)
{
    return (ts->scans * ts->scan_period_ns + 500u) / 1000u;
}

uint64_t ts_clock_us(ts_context *ts, uint32_t now_us)
{
    ts->clock_us += (uint32_t)(now_us - ts->clock_last); /* modulo 2^32 */
    ts->clock_last = now_us;
    return ts->clock_us;
}

void ts_begin(ts_context *ts, uint8_t kind)
{
    enc_begin(&ts->enc, ts->block, sizeof ts->block, ts->enc.write, ts->enc.user, kind);
}

void ts_write(ts_context *ts, const uint8_t *data, size_t len)
{
    while (len--) put(&ts->enc, *data++);
}

void ts_end(ts_context *ts)
{
    (void)enc_end(&ts->enc);
}

static void next_scan(ts_context *ts)
{
    ts->sequence = (uint16_t)(ts->sequence + 1u);
    ts->frames++;
    ts->scans++;
}

void ts_send_frame(ts_context *ts, uint64_t device_time_us, const uint16_t *counts)
{
    ts_begin(ts, TS_FRAME);
    enc_frame(&ts->enc, ts->sequence, device_time_us, ts->rows, ts->cols, counts);
    ts_end(ts);
    next_scan(ts);
}

void ts_drop_frame(ts_context *ts)
{
    next_scan(ts);
}

void ts_send_end(ts_context *ts)
{
    ts_begin(ts, TS_END);
    put_u16(&ts->enc, ts->frames ? (uint16_t)(ts->sequence - 1u) : 0u);
    put_u32(&ts->enc, ts->frames);
    ts_end(ts);
}

/* ---- IDENT: a JSON object ------------------------------------------------------ */

static void put_text(ts_context *ts, const char *text)
{
    while (*text) put(&ts->enc, (uint8_t)*text++);
}

static void put_decimal(ts_context *ts, uint64_t v)
{
    char digits[20];
    int n = 0;
    do {
        digits[n++] = (char)('0' + (int)(v % 10u));
        v /= 10u;
    } while (v);
    while (n) put(&ts->enc, (uint8_t)digits[--n]);
}

void ts_ident_text(ts_context *ts, const char *text, size_t len)
{
    static const char hex[] = "0123456789abcdef";
    while (len--) {
        uint8_t c = (uint8_t)*text++;
        if (c == '"' || c == '\\') {
            put(&ts->enc, '\\');
            put(&ts->enc, c);
        } else if (c == '\n') {
            put_text(ts, "\\n");
        } else if (c == '\t') {
            put_text(ts, "\\t");
        } else if (c == '\r') {
            put_text(ts, "\\r");
        } else if (c < 0x20u) {
            put_text(ts, "\\u00");
            put(&ts->enc, (uint8_t)hex[c >> 4]);
            put(&ts->enc, (uint8_t)hex[c & 15u]);
        } else {
            put(&ts->enc, c); /* UTF-8 passes through */
        }
    }
}

static size_t text_length(const char *text)
{
    size_t n = 0;
    while (text[n]) n++;
    return n;
}

static void put_string_field(ts_context *ts, const char *key, const char *value)
{
    put_text(ts, key);
    put(&ts->enc, '"');
    ts_ident_text(ts, value, text_length(value));
    put(&ts->enc, '"');
}

void ts_ident_begin(ts_context *ts, const char *device, const char *firmware, const char *serial)
{
    uint64_t millihertz = ts->scan_period_ns
        ? (1000000000000ULL + ts->scan_period_ns / 2u) / ts->scan_period_ns : 0u;
    ts_begin(ts, TS_IDENT);
    put_string_field(ts, "{\"device\":", device);
    put_string_field(ts, ",\"firmware\":", firmware);
    put_string_field(ts, ",\"serial\":", serial);
    put_text(ts, ",\"protocol\":1,\"rows\":");
    put_decimal(ts, ts->rows);
    put_text(ts, ",\"cols\":");
    put_decimal(ts, ts->cols);
    put_text(ts, ",\"frame_rate_hz\":");
    put_decimal(ts, millihertz / 1000u);
    put(&ts->enc, '.');
    put(&ts->enc, (uint8_t)('0' + (int)(millihertz / 100u % 10u)));
    put(&ts->enc, (uint8_t)('0' + (int)(millihertz / 10u % 10u)));
    put(&ts->enc, (uint8_t)('0' + (int)(millihertz % 10u)));
    put_text(ts, ",\"sensor_toml\":\"");
}

void ts_ident_end(ts_context *ts)
{
    put_text(ts, "\"}");
    ts_end(ts);
}

void ts_send_ident(ts_context *ts, const char *device, const char *firmware, const char *serial,
                   const char *sensor_toml)
{
    ts_ident_begin(ts, device, firmware, serial);
    ts_ident_text(ts, sensor_toml, text_length(sensor_toml));
    ts_ident_end(ts);
}

/* ---- the host's commands ------------------------------------------------------- */

uint8_t ts_receive(ts_context *ts, uint8_t byte)
{
    size_t n = ts->rx_len, i = 0, o = 0;
    uint32_t crc;
    if (byte != 0) {
        if (ts->rx_len < TS_RX_MAX) ts->rx[ts->rx_len++] = byte;
        else ts->rx_skip = 1; /* too long for a command: drop it at the delimiter */
        return 0;
    }
    ts->rx_len = 0;
    if (ts->rx_skip || n == 0) {
        ts->rx_skip = 0;
        return 0;
    }
    while (i < n) { /* COBS-decode in place: o never passes i */
        uint8_t code = ts->rx[i++], k;
        for (k = 1; k < code; k++) {
            if (i >= n) return 0; /* a block cut short */
            ts->rx[o++] = ts->rx[i++];
        }
        if (code < 255 && i < n) ts->rx[o++] = 0;
    }
    if (o < 6 || ts->rx[0] != TS_PROTOCOL_VERSION) return 0;
    if (ts->rx[1] != TS_IDENTIFY && ts->rx[1] != TS_START && ts->rx[1] != TS_STOP) return 0;
    crc = ts_crc32(0, ts->rx, o - 4);
    if (crc != ((uint32_t)ts->rx[o - 4] | (uint32_t)ts->rx[o - 3] << 8 |
                (uint32_t)ts->rx[o - 2] << 16 | (uint32_t)ts->rx[o - 1] << 24))
        return 0;
    return ts->rx[1];
}
