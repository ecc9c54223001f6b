/* The base drive the states share (host/task/drive.py). */
#include "task_drive.h"

#include "fixedpoint.h"

int32_t mg_task_wrap_mrad(int64_t a_mrad)
{
    return (int32_t)(mg_floor_mod(a_mrad + 3142, 6283) - 3142);
}
