// sdfcsg: Constructive Solid Geometry on signed distance fields, computed with Vulkan.
#pragma once

#define SDFCSG_VERSION_MAJOR 0
#define SDFCSG_VERSION_MINOR 1
#define SDFCSG_VERSION_PATCH 0

#include "sdfcsg/camera.h"
#include "sdfcsg/compile.h"
#include "sdfcsg/context.h"
#include "sdfcsg/error.h"
#include "sdfcsg/eval.h"
#include "sdfcsg/export.h"
#include "sdfcsg/generate.h"
#include "sdfcsg/io.h"
#include "sdfcsg/mesh.h"
#include "sdfcsg/mesh_report.h"
#include "sdfcsg/model.h"
#include "sdfcsg/nodes.h"
#include "sdfcsg/render.h"
#include "sdfcsg/scene.h"
