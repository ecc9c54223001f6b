/* The lockstep channel's messages on the host's side (cosim/lockstep.py, docs/cosim.md): the
 * 13-byte header (magic "MGLS", kind u8, metadata and blob lengths u32, little-endian), GRANT
 * (compact binary or JSON, its frames in the blob or in the shared frame ring) and END read,
 * HELLO, DONE (compact when it has no events and no finished load window, else JSON) and BYE
 * written byte for byte as the Python codec writes them. */
#ifndef MOBIGRASP_HOSTC_LOCKSTEP_H
#define MOBIGRASP_HOSTC_LOCKSTEP_H

#include <stddef.h>
#include <stdint.h>

#define MG_LS_VERSION 2
#define MG_LS_HEADER_BYTES 13
#define MG_LS_MAX_META (16u << 20)
#define MG_LS_MAX_BLOB (64u << 20)
#define MG_LS_MAX_CHUNKS 64 /* UART chunks of one grant, writes of one DONE */
#define MG_LS_MAX_FRAMES 8  /* frames of one grant */
#define MG_LS_PATH_MAX 256

enum {
    MG_LS_HELLO = 1, MG_LS_GRANT = 2, MG_LS_DONE = 3, MG_LS_END = 4, MG_LS_BYE = 5,
    MG_LS_GRANT_COMPACT = 6, MG_LS_DONE_COMPACT = 7
};

typedef struct {
    int64_t t_us;
    uint32_t nbytes;
} mg_ls_chunk_t;

typedef struct {
    int64_t seq, capture_us, arrival_us;
    int64_t width, height, channels;
    int64_t offset, nbytes; /* into the blob, unless shared */
    int32_t shared;         /* the pixels are in the frame ring: path and its offset */
    char path[MG_LS_PATH_MAX];
    int64_t shared_offset;
} mg_ls_frame_t;

typedef struct {
    int64_t start_us, until_us;
    int32_t n_uart;
    mg_ls_chunk_t uart[MG_LS_MAX_CHUNKS];
    int32_t n_frames;
    mg_ls_frame_t frames[MG_LS_MAX_FRAMES];
} mg_ls_grant_t;

typedef struct {
    int64_t at_us;
    char reason[128];
} mg_ls_end_t;

/* What a DONE says (cosim/lockstep.py Done and the host's load). events: the JSON objects of
 * the trace events, comma-separated (n_events of them); windows: the load windows finished in
 * this quantum, their indices and their busy fraction in millionths. */
typedef struct {
    int64_t until_us;
    int32_t n_writes;
    const mg_ls_chunk_t *writes;
    int32_t n_events;
    const char *events;
    size_t events_len;
    int64_t window_us;
    int32_t n_windows;
    const int64_t *window_index;
    const int64_t *window_micro;
    const char *state;
    int32_t finished, camera;
    int64_t quiet_until;
} mg_ls_done_t;

/* 0, or -1 when the header is not one (magic, kind, sizes) */
int mg_ls_decode_header(const uint8_t *h, int32_t *kind, uint32_t *meta_len,
                        uint32_t *blob_len);
/* a GRANT of either kind from its metadata (blob_len: the blob's size, for the frames' bounds):
 * 0, or -1 when it is malformed (as cosim/lockstep.py's LockstepError) */
int mg_ls_decode_grant(int32_t kind, const uint8_t *meta, uint32_t n, uint32_t blob_len,
                       mg_ls_grant_t *g);
int mg_ls_decode_end(const uint8_t *meta, uint32_t n, mg_ls_end_t *e);
/* the wire bytes written to out: their count, or 0 when cap is too small */
size_t mg_ls_encode_hello(uint8_t *out, size_t cap, const char *host_id);
size_t mg_ls_encode_done(uint8_t *out, size_t cap, const mg_ls_done_t *d);
size_t mg_ls_encode_bye(uint8_t *out, size_t cap, const char *stats_json, size_t n);

#endif
