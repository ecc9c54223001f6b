/* The lockstep driver of the C host (drivers/lockstep.py): the rig grants the host a quantum
 * of simulated time; the driver hands the program the quantum's UART bytes with their arrival
 * times and its camera frames (from the GRANT's blob or the shared frame ring,
 * cosim/frame_ring.py), runs it up to until_us and never beyond, writes what it sent to the
 * serial port and answers DONE with the chunks' send times, the trace events and the load.
 * mg_lockstep_serve is the quantum without I/O; mg_lockstep_run the whole run over the Unix
 * socket and the serial port, with sys.h. */
#ifndef MOBIGRASP_HOSTC_LOCKSTEP_DRIVER_H
#define MOBIGRASP_HOSTC_LOCKSTEP_DRIVER_H

#include <stddef.h>
#include <stdint.h>

#include "app.h"
#include "lockstep.h"

#define MG_LS_OUT_BYTES 4096   /* UART bytes the host writes in one quantum */
#define MG_LS_DONE_BYTES 65536 /* one encoded DONE */
#define MG_LS_RINGS 2          /* frame ring files mapped */
#define MG_LS_RING_MAP ((size_t)MG_LS_MAX_BLOB) /* address space mapped for one ring */

typedef struct {
    char path[MG_LS_PATH_MAX];
    const uint8_t *base;
    size_t len;
} mg_ls_ring_t;

typedef struct {
    mg_app_t *app;
    int64_t clock_us;   /* the start of the grant being served, then its end */
    int64_t loads_sent; /* load windows reported so far */
    uint8_t out[MG_LS_OUT_BYTES];
    size_t out_len;     /* the UART bytes of the last quantum */
    char events[MG_EVENTS_BYTES];
    int32_t n_rings;
    mg_ls_ring_t rings[MG_LS_RINGS];
} mg_lockstep_t;

void mg_lockstep_init(mg_lockstep_t *ls, mg_app_t *app);
/* One grant: uart holds its grant's UART bytes (the sum of its chunks), pixels[i] frame i's
 * (NULL or none for a frame slot that passed with the camera off). Writes the DONE to done
 * (its length, 0 when it does not fit) and the UART bytes to ls->out. */
size_t mg_lockstep_serve(mg_lockstep_t *ls, const mg_ls_grant_t *g, const uint8_t *uart,
                         const uint8_t *const *pixels, uint8_t *done, size_t cap);
/* The whole run: HELLO, then GRANTs served until END, answered by BYE (stats_json: the
 * program's statistics). Returns 0 at END, or a negative errno / -1 for a malformed message;
 * *why names what went wrong. */
int mg_lockstep_run(mg_lockstep_t *ls, int sock_fd, int serial_fd, const char **why);

#endif
