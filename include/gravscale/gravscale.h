/* gravscale.h - metric size from free flight in uncalibrated video: the core. */
#ifndef GRAVSCALE_H
#define GRAVSCALE_H

#include "gs_types.h"
#include "gs_time.h"
#include "gs_num.h"
#include "gs_ring.h"
#include "gs_com.h"
#include "gs_fit.h"
#include "gs_event.h"
#include "gs_emit.h"
#include "gs_config.h"
#include "gs_agg.h"
#include "gs_flight.h"
#include "gs_pipeline.h"

#endif
