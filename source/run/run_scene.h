#ifndef hysteron_run_run_scene_h
#define hysteron_run_run_scene_h

#include "base/run_record.h"
#include <hysteron/scene/scene.h>

namespace hysteron
{
  namespace Run
  {
    /**
     * Run a parsed scene: refuse a directory in use and an impossible --resume,
     * set up the method (no file written yet), then prepare the output directory
     * (lock, the previous run's files removed, manifest, parameters.prm), run the
     * method, record its status in the manifest, and print the summary and the
     * timer table. What `hysteron scene.prm` does after parsing. @p record, the
     * run's record of its files, must outlive the scene (whose method's tables
     * are registered in it).
     */
    template <int dim>
    void
    run_scene(Scene<dim> &scene, Output::RunRecord &record);
  } // namespace Run
} // namespace hysteron

#endif
