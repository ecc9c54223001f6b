/* What the task reads from the camera and the odometry (host/task/sense.py): the camera's
 * axes and the pixel ray to the platform frame (eqs. (1)-(3) of 000 with the wrist roll), 002's
 * bearing e of the double cross, d_pixel in whole px, and the platform <-> odometry frames.
 * Angles in mrad, rotations Q12, lengths Q4 mm where named so. */
#ifndef MOBIGRASP_HOSTC_TASK_SENSE_H
#define MOBIGRASP_HOSTC_TASK_SENSE_H

#include <stdint.h>

#include "kinematics.h"
#include "task_machine.h"

/* camera x (right), y (down), z (optical axis) in the platform frame, Q12 */
void mg_camera_axes_q12(const int32_t joints_mrad[6], int32_t axes[3][3]);
/* the point seen at pixel (u, v) (Q4 px) at depth (Q4 mm), in the platform frame, Q4 mm */
void mg_pixel_to_platform_mm_q4(const mg_arm_geometry_t *g, const int32_t joints_mrad[6],
                                const mg_camera_model_t *cam, int32_t u_q4, int32_t v_q4,
                                int32_t depth_mm_q4, int32_t out_q4[3]);
/* both "+" centres of a dual "+" (uv: u1, v1, u2, v2 in Q4 px; dist_mm: its depth) in the
 * platform frame, Q4 mm, at its depth; has_top: each where its pixel ray meets the plane
 * z = top_q4 (the object's top) instead, so that a pair seen obliquely along the view is not
 * shortened to one depth (sense.py plus_positions); 1, or 0 when not usable */
int mg_plus_positions(const mg_arm_geometry_t *g, const int32_t joints_mrad[6],
                      const mg_camera_model_t *cam, const int32_t uv_q4[4], int32_t dist_mm,
                      int32_t has_top, int32_t top_q4, int32_t out_q4[2][3]);
/* 002's e: the bearing of the image column um_q4 from the platform heading, right positive */
int32_t mg_bearing_mrad(int32_t um_q4, int32_t theta5_mrad, const mg_camera_model_t *cam);
int32_t mg_d_pixel_px(int32_t d_pixel_q4); /* Q4 px to whole px, rounded */
/* odometry-frame (x, y) mm of a platform-frame point (Y_r forward, X_r right, Q4 mm) */
void mg_platform_to_odom_mm(int32_t x_mm, int32_t y_mm, int32_t heading_mrad,
                            int32_t mount_forward_mm, const int32_t p_q4[3], int32_t out_mm[2]);
/* platform-frame (X_r, Y_r) in Q4 mm of an odometry-frame point */
void mg_odom_to_platform_q4(int32_t x_mm, int32_t y_mm, int32_t heading_mrad,
                            int32_t mount_forward_mm, int32_t obj_x_mm, int32_t obj_y_mm,
                            int32_t out_q4[2]);

#endif
