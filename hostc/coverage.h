/* Stations of the wandering search: concentric rings that cover a disc once
 * (host/coverage.py, whose docstring gives the layout and why). Integer mm and mrad in the
 * frame of the start (x ahead, y left). */
#ifndef MOBIGRASP_HOSTC_COVERAGE_H
#define MOBIGRASP_HOSTC_COVERAGE_H

#include <stdint.h>

#define MG_COVER_STATIONS 256 /* stations of all the rings */
#define MG_COVER_MAX_RINGS 64 /* rings at most (more: overflow) */

/* the stations (x_mm, y_mm) from the start (excluded) round the rings out to radius_mm, the
 * last ring at radius_mm - edge_mm (edge_mm 0: view_mm): their count (0: the look-around at
 * the start sees it all), or -1 when view_mm or chord_mm <= 0, radius_mm or edge_mm < 0 or the
 * sides are too long for the strip to get a ring farther out; stations past max, or rings
 * past MG_COVER_MAX_RINGS, set *overflow */
int32_t mg_ring_stations(int32_t radius_mm, int32_t view_mm, int32_t chord_mm, int32_t edge_mm,
                         int32_t out[][2], int32_t max, int32_t *overflow);
/* (turn_mrad, drive_mm) from pose (x_mm, y_mm, heading_mrad) to station: the turn in
 * [-pi, pi), left positive */
void mg_leg_to(const int32_t pose[3], const int32_t station[2], int32_t *turn_mrad,
               int32_t *drive_mm);
/* a point of the start's frame in odometry, the start being origin (x, y, heading) */
void mg_to_odometry(const int32_t origin[3], const int32_t xy[2], int32_t out[2]);

#endif
