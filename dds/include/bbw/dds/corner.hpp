// The corner id on the wire is bbw::Corner (bbw/common/corner.hpp); these names keep the DDS
// edge's spelling.
#pragma once

#include "bbw/common/corner.hpp"

namespace bbw::dds {

using bbw::Corner;
using bbw::corner_from_wire;
using bbw::corner_index;
using bbw::corner_name;
using bbw::is_front;
using bbw::kAllCorners;
using bbw::kCornerCount;
using bbw::parse_corner;

}  // namespace bbw::dds
