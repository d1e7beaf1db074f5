// FrameSource is an interface; this file anchors its vtable.
#include "lumar/capture/frame_source.h"
