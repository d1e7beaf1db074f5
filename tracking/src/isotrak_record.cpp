#include "lumar/tracking/isotrak_record.h"

#include <string>

#include "lumar/base/error.h"

namespace lumar::tracking {

void validate_output_format(const OutputFormat& format) {
  int position = 0, attitude = 0, quaternion = 0;
  for (int item : format.output_list) {
    switch (item) {
      case kItemSpace:
      case kItemCrLf:
        break;
      case kItemPosition:
        ++position;
        break;
      case kItemAttitude:
        ++attitude;
        break;
      case kItemQuaternion:
        ++quaternion;
        break;
      default:
        throw InputError("Polhemus output list: item " + std::to_string(item) +
                         " is not supported; use items 0, 1, 2, 4 and 11");
    }
  }
  if (position + attitude + quaternion == 0)
    throw InputError(
        "Polhemus output list: it holds no data item; include 2 (position), 4 (attitude) or 11 (quaternion)");
  if (position > 1 || attitude > 1 || quaternion > 1)
    throw InputError("Polhemus output list: items 2, 4 and 11 may each appear only once; remove the repeat");
}

}  // namespace lumar::tracking
