/*
 * tactsense.c - the tactsense wire protocol, versions 1 and 2, for the device side.
 * See tactsense.h for the API and docs/protocol.md for the protocol.
 */
#include "tactsense.h"

#ifdef TS_CRC_BYTE_TABLE
/* CRC-32/ISO-HDLC, reflected polynomial 0xEDB88320, a byte at a time: a table of
   256 words (1 KB), about twice as fast as the default. */
static const uint32_t ts_crc_byte[256] = {
    0x00000000UL, 0x77073096UL, 0xee0e612cUL, 0x990951baUL, 0x076dc419UL, 0x706af48fUL,
    0xe963a535UL, 0x9e6495a3UL, 0x0edb8832UL, 0x79dcb8a4UL, 0xe0d5e91eUL, 0x97d2d988UL,
    0x09b64c2bUL, 0x7eb17cbdUL, 0xe7b82d07UL, 0x90bf1d91UL, 0x1db71064UL, 0x6ab020f2UL,
    0xf3b97148UL, 0x84be41deUL, 0x1adad47dUL, 0x6ddde4ebUL, 0xf4d4b551UL, 0x83d385c7UL,
    0x136c9856UL, 0x646ba8c0UL, 0xfd62f97aUL, 0x8a65c9ecUL, 0x14015c4fUL, 0x63066cd9UL,
    0xfa0f3d63UL, 0x8d080df5UL, 0x3b6e20c8UL, 0x4c69105eUL, 0xd56041e4UL, 0xa2677172UL,
    0x3c03e4d1UL, 0x4b04d447UL, 0xd20d85fdUL, 0xa50ab56bUL, 0x35b5a8faUL, 0x42b2986cUL,
    0xdbbbc9d6UL, 0xacbcf940UL, 0x32d86ce3UL, 0x45df5c75UL, 0xdcd60dcfUL, 0xabd13d59UL,
    0x26d930acUL, 0x51de003aUL, 0xc8d75180UL, 0xbfd06116UL, 0x21b4f4b5UL, 0x56b3c423UL,
    0xcfba9599UL, 0xb8bda50fUL, 0x2802b89eUL, 0x5f058808UL, 0xc60cd9b2UL, 0xb10be924UL,
    0x2f6f7c87UL, 0x58684c11UL, 0xc1611dabUL, 0xb6662d3dUL, 0x76dc4190UL, 0x01db7106UL,
    0x98d220bcUL, 0xefd5102aUL, 0x71b18589UL, 0x06b6b51fUL, 0x9fbfe4a5UL, 0xe8b8d433UL,
    0x7807c9a2UL, 0x0f00f934UL, 0x9609a88eUL, 0xe10e9818UL, 0x7f6a0dbbUL, 0x086d3d2dUL,
    0x91646c97UL, 0xe6635c01UL, 0x6b6b51f4UL, 0x1c6c6162UL, 0x856530d8UL, 0xf262004eUL,
    0x6c0695edUL, 0x1b01a57bUL, 0x8208f4c1UL, 0xf50fc457UL, 0x65b0d9c6UL, 0x12b7e950UL,
    0x8bbeb8eaUL, 0xfcb9887cUL, 0x62dd1ddfUL, 0x15da2d49UL, 0x8cd37cf3UL, 0xfbd44c65UL,
    0x4db26158UL, 0x3ab551ceUL, 0xa3bc0074UL, 0xd4bb30e2UL, 0x4adfa541UL, 0x3dd895d7UL,
    0xa4d1c46dUL, 0xd3d6f4fbUL, 0x4369e96aUL, 0x346ed9fcUL, 0xad678846UL, 0xda60b8d0UL,
    0x44042d73UL, 0x33031de5UL, 0xaa0a4c5fUL, 0xdd0d7cc9UL, 0x5005713cUL, 0x270241aaUL,
    0xbe0b1010UL, 0xc90c2086UL, 0x5768b525UL, 0x206f85b3UL, 0xb966d409UL, 0xce61e49fUL,
    0x5edef90eUL, 0x29d9c998UL, 0xb0d09822UL, 0xc7d7a8b4UL, 0x59b33d17UL, 0x2eb40d81UL,
    0xb7bd5c3bUL, 0xc0ba6cadUL, 0xedb88320UL, 0x9abfb3b6UL, 0x03b6e20cUL, 0x74b1d29aUL,
    0xead54739UL, 0x9dd277afUL, 0x04db2615UL, 0x73dc1683UL, 0xe3630b12UL, 0x94643b84UL,
    0x0d6d6a3eUL, 0x7a6a5aa8UL, 0xe40ecf0bUL, 0x9309ff9dUL, 0x0a00ae27UL, 0x7d079eb1UL,
    0xf00f9344UL, 0x8708a3d2UL, 0x1e01f268UL, 0x6906c2feUL, 0xf762575dUL, 0x806567cbUL,
    0x196c3671UL, 0x6e6b06e7UL, 0xfed41b76UL, 0x89d32be0UL, 0x10da7a5aUL, 0x67dd4accUL,
    0xf9b9df6fUL, 0x8ebeeff9UL, 0x17b7be43UL, 0x60b08ed5UL, 0xd6d6a3e8UL, 0xa1d1937eUL,
    0x38d8c2c4UL, 0x4fdff252UL, 0xd1bb67f1UL, 0xa6bc5767UL, 0x3fb506ddUL, 0x48b2364bUL,
    0xd80d2bdaUL, 0xaf0a1b4cUL, 0x36034af6UL, 0x41047a60UL, 0xdf60efc3UL, 0xa867df55UL,
    0x316e8eefUL, 0x4669be79UL, 0xcb61b38cUL, 0xbc66831aUL, 0x256fd2a0UL, 0x5268e236UL,
    0xcc0c7795UL, 0xbb0b4703UL, 0x220216b9UL, 0x5505262fUL, 0xc5ba3bbeUL, 0xb2bd0b28UL,
    0x2bb45a92UL, 0x5cb36a04UL, 0xc2d7ffa7UL, 0xb5d0cf31UL, 0x2cd99e8bUL, 0x5bdeae1dUL,
    0x9b64c2b0UL, 0xec63f226UL, 0x756aa39cUL, 0x026d930aUL, 0x9c0906a9UL, 0xeb0e363fUL,
    0x72076785UL, 0x05005713UL, 0x95bf4a82UL, 0xe2b87a14UL, 0x7bb12baeUL, 0x0cb61b38UL,
    0x92d28e9bUL, 0xe5d5be0dUL, 0x7cdcefb7UL, 0x0bdbdf21UL, 0x86d3d2d4UL, 0xf1d4e242UL,
    0x68ddb3f8UL, 0x1fda836eUL, 0x81be16cdUL, 0xf6b9265bUL, 0x6fb077e1UL, 0x18b74777UL,
    0x88085ae6UL, 0xff0f6a70UL, 0x66063bcaUL, 0x11010b5cUL, 0x8f659effUL, 0xf862ae69UL,
    0x616bffd3UL, 0x166ccf45UL, 0xa00ae278UL, 0xd70dd2eeUL, 0x4e048354UL, 0x3903b3c2UL,
    0xa7672661UL, 0xd06016f7UL, 0x4969474dUL, 0x3e6e77dbUL, 0xaed16a4aUL, 0xd9d65adcUL,
    0x40df0b66UL, 0x37d83bf0UL, 0xa9bcae53UL, 0xdebb9ec5UL, 0x47b2cf7fUL, 0x30b5ffe9UL,
    0xbdbdf21cUL, 0xcabac28aUL, 0x53b39330UL, 0x24b4a3a6UL, 0xbad03605UL, 0xcdd70693UL,
    0x54de5729UL, 0x23d967bfUL, 0xb3667a2eUL, 0xc4614ab8UL, 0x5d681b02UL, 0x2a6f2b94UL,
    0xb40bbe37UL, 0xc30c8ea1UL, 0x5a05df1bUL, 0x2d02ef8dUL};

static uint32_t crc_step(uint32_t crc, uint8_t byte)
{
    return (crc >> 8) ^ ts_crc_byte[(crc ^ byte) & 0xFFu];
}
#else
/* CRC-32/ISO-HDLC, reflected polynomial 0xEDB88320, four bits at a time: a table
   of 16 words (64 bytes) instead of 256 (1 KB; define TS_CRC_BYTE_TABLE for it). */
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
#endif

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
                      uint8_t version, uint8_t kind)
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
    put(e, version);
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

/* A FRAME's body: version 1 (one reading per taxel, no components byte) or version 2
   (the components byte, then rows * cols * components readings). */
static void enc_frame(ts_encoder *e, uint16_t sequence, uint64_t time_us, uint8_t rows,
                      uint8_t cols, uint8_t version, uint8_t components, const uint16_t *counts)
{
    size_t i, n = (size_t)rows * cols * (version == TS_PROTOCOL_VERSION ? 1u : components);
    put_u16(e, sequence);
    put_u64(e, time_us);
    put(e, rows);
    put(e, cols);
    if (version != TS_PROTOCOL_VERSION) put(e, components);
    for (i = 0; i < n; i++) put_u16(e, counts[i]);
}

size_t ts_encode_frame(uint8_t *out, size_t cap, uint16_t sequence, uint64_t device_time_us,
                       uint8_t rows, uint8_t cols, const uint16_t *counts)
{
    ts_encoder e;
    if (rows == 0 || cols == 0 || counts == NULL) return 0;
    enc_begin(&e, out, cap, NULL, NULL, TS_PROTOCOL_VERSION, TS_FRAME);
    enc_frame(&e, sequence, device_time_us, rows, cols, TS_PROTOCOL_VERSION, 1u, counts);
    return enc_end(&e);
}

size_t ts_encode_frame_v2(uint8_t *out, size_t cap, uint16_t sequence, uint64_t device_time_us,
                          uint8_t rows, uint8_t cols, uint8_t components,
                          const uint16_t *counts)
{
    ts_encoder e;
    if (rows == 0 || cols == 0 || counts == NULL) return 0;
    if (components == 0 || components > TS_MAX_COMPONENTS) return 0;
    enc_begin(&e, out, cap, NULL, NULL, TS_PROTOCOL_VERSION_2, TS_FRAME);
    enc_frame(&e, sequence, device_time_us, rows, cols, TS_PROTOCOL_VERSION_2, components,
              counts);
    return enc_end(&e);
}

size_t ts_encode_end(uint8_t *out, size_t cap, uint16_t last_sequence, uint32_t frames)
{
    ts_encoder e;
    enc_begin(&e, out, cap, NULL, NULL, TS_PROTOCOL_VERSION, TS_END);
    put_u16(&e, last_sequence);
    put_u32(&e, frames);
    return enc_end(&e);
}

size_t ts_encode_packet(uint8_t *out, size_t cap, uint8_t kind, const uint8_t *body,
                        size_t body_len)
{
    ts_encoder e;
    size_t i;
    enc_begin(&e, out, cap, NULL, NULL, TS_PROTOCOL_VERSION, kind);
    for (i = 0; i < body_len; i++) put(&e, body[i]);
    return enc_end(&e);
}

/* ---- the device context ------------------------------------------------------ */

void ts_init(ts_context *ts, uint8_t rows, uint8_t cols, uint32_t scan_period_ns,
             ts_write_fn write, void *user)
{
    ts->rows = rows;
    ts->cols = cols;
    ts->components = 1u;
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

int ts_set_components(ts_context *ts, uint8_t components)
{
    if (components == 0 || components > TS_MAX_COMPONENTS) return -1;
    ts->components = components;
    return 0;
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
    uint8_t version = kind == TS_FRAME && ts->components > 1 ? TS_PROTOCOL_VERSION_2
                                                             : TS_PROTOCOL_VERSION;
    enc_begin(&ts->enc, ts->block, sizeof ts->block, ts->enc.write, ts->enc.user, version,
              kind);
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
    enc_frame(&ts->enc, ts->sequence, device_time_us, ts->rows, ts->cols,
              ts->components > 1 ? TS_PROTOCOL_VERSION_2 : TS_PROTOCOL_VERSION, ts->components,
              counts);
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

/* One byte of a JSON string, escaped. */
static void put_escaped(ts_context *ts, uint8_t c)
{
    static const char hex[] = "0123456789abcdef";
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

void ts_ident_text(ts_context *ts, const char *text, size_t len)
{
    while (len--) put_escaped(ts, (uint8_t)*text++);
}

/* A NUL-terminated string, escaped, in one pass: no length is counted first, since
   GCC turns a counting loop into a call of strlen at -O2, -O3 and -Os (the library
   calls nothing outside itself; tests/firmware/test_freestanding.py checks it). */
static void put_escaped_text(ts_context *ts, const char *text)
{
    while (*text) put_escaped(ts, (uint8_t)*text++);
}

static void put_string_field(ts_context *ts, const char *key, const char *value)
{
    put_text(ts, key);
    put(&ts->enc, '"');
    put_escaped_text(ts, value);
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
    put_text(ts, ",\"protocol\":");
    put_decimal(ts, ts->components > 1 ? TS_PROTOCOL_VERSION_2 : TS_PROTOCOL_VERSION);
    put_text(ts, ",\"rows\":");
    put_decimal(ts, ts->rows);
    put_text(ts, ",\"cols\":");
    put_decimal(ts, ts->cols);
    if (ts->components > 1) {
        put_text(ts, ",\"components\":");
        put_decimal(ts, ts->components);
    }
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
    put_escaped_text(ts, sensor_toml);
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
    if (o < 6 || (ts->rx[0] != TS_PROTOCOL_VERSION && ts->rx[0] != TS_PROTOCOL_VERSION_2))
        return 0;
    if (ts->rx[1] != TS_IDENTIFY && ts->rx[1] != TS_START && ts->rx[1] != TS_STOP) return 0;
    crc = ts_crc32(0, ts->rx, o - 4);
    if (crc != ((uint32_t)ts->rx[o - 4] | (uint32_t)ts->rx[o - 3] << 8 |
                (uint32_t)ts->rx[o - 2] << 16 | (uint32_t)ts->rx[o - 1] << 24))
        return 0;
    return ts->rx[1];
}
