// cli::figure_painter() (cli_common.h).
#include "cli_common.h"

#if SDPSLAM_HAVE_PLOT
#include "sdpslam/plot/plot.h"
#endif

namespace sdpslam::cli {

io::Painter figure_painter() {
#if SDPSLAM_HAVE_PLOT
  return plot::painter();
#else
  return io::plain_painter();
#endif
}

}  // namespace sdpslam::cli
