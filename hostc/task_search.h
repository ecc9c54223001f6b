/* SEARCH and LOST (host/task/search.py): the arm search of 000 Fig. 5 (search.c), its wander
 * on the coverage rings and its sighting memory, the confirmation of a sighting, the stop and
 * the search again after a loss (000 section III.B.2). Integer mm / us; no I/O. */
#ifndef MOBIGRASP_HOSTC_TASK_SEARCH_H
#define MOBIGRASP_HOSTC_TASK_SEARCH_H

#include <stdint.h>

#include "task_machine.h"

void mg_task_enter_search(mg_task_t *t, int64_t now_us, const mg_task_inputs_t *in);
void mg_task_do_search(mg_task_t *t, int64_t now_us, const mg_task_inputs_t *in);
void mg_task_enter_lost(mg_task_t *t, int64_t now_us, const mg_task_inputs_t *in);
void mg_task_do_lost(mg_task_t *t, int64_t now_us, const mg_task_inputs_t *in);
/* 000/001: an unconfirmed sighting seen again at its place (within sighting_match_mm) */
int mg_task_seen_there_before(const mg_task_t *t);

#endif
