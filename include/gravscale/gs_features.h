/* gs_features.h - compile-time selection of per-device features. Every one
 * defaults to 1 (everything in: hosts, tests and the default firmware); a device
 * build turns off what its hardware never uses, e.g. -DGS_WITH_NMEA=0 (CMake:
 * -DGS_FEATURES="GS_WITH_NMEA=0;GS_WITH_BLAZEPOSE33=0"). A feature that is off
 * behaves as unsupported, never differently: its layout is unknown to
 * gs_layout_kp_count (gs_pipeline_init returns GS_EINVAL), its format name is
 * rejected by the profile parser and gs_emit writes nothing for it. What is on
 * gives the same bytes as in the full build. docs/firmware.md has the sizes. */
#ifndef GS_FEATURES_H
#define GS_FEATURES_H

/* output line formats (gs_emit.h) */
#ifndef GS_WITH_JSON
#define GS_WITH_JSON 1
#endif
#ifndef GS_WITH_NMEA
#define GS_WITH_NMEA 1
#endif
/* keypoint layouts (gs_com.h): one tracked point (a ball), with its flights' sub-frame
 * boundaries from the COM's contact model (a body's come from its feet) */
#ifndef GS_WITH_POINT
#define GS_WITH_POINT 1
#endif
#ifndef GS_WITH_COCO17
#define GS_WITH_COCO17 1
#endif
#ifndef GS_WITH_BLAZEPOSE33
#define GS_WITH_BLAZEPOSE33 1
#endif
/* the fit method "ransac" (fit = ransac; irls and plain are always in) */
#ifndef GS_WITH_RANSAC
#define GS_WITH_RANSAC 1
#endif
/* trace events (gs_pipeline_set_trace: state, sample and fit events, for
 * debugging); off, the core emits none and gs_pipeline_set_trace has no effect */
#ifndef GS_WITH_TRACE
#define GS_WITH_TRACE 1
#endif
/* a skeleton layout: the COM model, the standing tracker, visits (sessions) */
#define GS_WITH_POSE (GS_WITH_COCO17 || GS_WITH_BLAZEPOSE33)

#if !GS_WITH_POINT && !GS_WITH_POSE
#error "gs_features.h: at least one layout (GS_WITH_POINT, GS_WITH_COCO17, GS_WITH_BLAZEPOSE33)"
#endif
#if !GS_WITH_JSON && !GS_WITH_NMEA
#error "gs_features.h: at least one output format (GS_WITH_JSON, GS_WITH_NMEA)"
#endif

#endif
