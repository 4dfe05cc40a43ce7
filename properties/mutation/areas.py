"""Which engine modules each mutation area mutates, and which property files may kill their mutants.

The map follows engine/ARCHITECTURE.md (module -> property file). mutmut 3 then narrows it further by itself: a
stats run records which tests call which (trampolined) function, and each mutant runs only those tests.

Each area has
- ``mutate``: glob patterns of the modules whose mutants are made (mutmut's ``only_mutate``);
- ``skip`` (optional): glob patterns left out of them (mutmut's ``do_not_mutate``), with the reason beside them;
- ``tests``: the property files run against its mutants (a file that does not exist in the checkout is left out
  by the driver, so that an area can name the files of a branch that is not merged yet);
- ``sample``: the default 1-in-K sample of ``tox -e mutation`` (chosen so that the six areas fit a nightly job;
  the measured times are in properties/MUTATION.md). ``--sample K`` on the command line overrides it.

``DESELECT`` lists the tests left out of the mutation run, each with its reason: with NUMBA_DISABLE_JIT=1 every
kernel is interpreted, and these tests take minutes per run (benchmark-sized inputs, or simulations of 1e5 RK4
steps per example). They still run in CI (`tox`), compiled.
"""
from __future__ import annotations

AREAS: dict[str, dict[str, list[str]]] = {
    "dynamics": {
        "mutate": ["engine/dynamics/*"],
        "tests": [
            "properties/test_rk4.py",
            "properties/test_bisection.py",
            "properties/test_falling.py",
            "properties/test_bisection_edges.py",
            "properties/test_state_vector_layout.py",
            "properties/test_falling_cube_edges.py",
            "properties/test_impact_tolerance.py",
            # plot_fall (plot.py), reached by no other file of the area
            "properties/test_plot_fall.py",
            # written against the dynamics run on the current code (properties/MUTATION.md, dynamics)
            "properties/test_rk4_slopes.py",
            # written against the dynamics run on 553feb3 (properties/MUTATION.md, dynamics)
            "properties/test_fall_argument_names.py",
        ],
        "sample": 10,
    },
    "broadphase": {
        "mutate": ["engine/broadphase/*"],
        "tests": [
            "properties/test_broadphase.py",
            "properties/test_broadphase_stateful.py",
            "properties/test_broadphase_spheres.py",
            "properties/test_broadphase_kinematic.py",
            "properties/test_dynamic_tree_edges.py",
            "properties/test_kinematic_inputs.py",
            "properties/test_dynamic_tree_quality.py",
            "properties/test_broadphase_large_grids.py",
            "properties/test_broadphase_helpers.py",
            "properties/test_broadphase_api_edges.py",
            "properties/test_broadphase_pruning.py",
            "properties/test_broadphase_threads.py",
            "properties/test_broadphase_big_levels.py",
            # written against the survivors of the broadphase run on af5c9c5 (properties/MUTATION.md)
            "properties/test_kinematic_cull_rule.py",
            "properties/test_sap_sparse_columns.py",
            "properties/test_sap_sweep_order.py",
            # the padded cell grid of sphere_pairs on dense scenes (sphere_cells.py)
            "properties/test_broadphase_sphere_cells.py",
            "properties/test_sphere_pairs_work_arrays.py",
            # written against the survivors of the broadphase runs on 7a481eb / 4a77c01 (properties/MUTATION.md)
            "properties/test_sap_keys_and_columns.py",
            "properties/test_sphere_column_ranges.py",
        ],
        # 1 in 60 (109 of 6727 mutants; a third of the 1-in-20 sample, since 60 is a multiple of 20): its stats and
        # clean runs interpret the whole area suite twice (about 45 min at load 6 on 2 cores), so 1 in 20 does
        # not fit a nightly job
        "sample": 60,
    },
    "gas": {
        "mutate": ["engine/gas/*"],
        "tests": [
            "properties/test_gas_elastic.py",
            "properties/test_gas_simulation.py",
            "properties/test_gas_observables.py",
            "properties/test_gas_kinetic_theory.py",
            "properties/test_gas_argument_names.py",
            "properties/test_gas_stepped_response.py",
            # the event calendar and the neighbour-list search (engine/gas/event_queue.py, neighbour_list.py)
            "properties/test_gas_event_calendar.py",
            "properties/test_gas_neighbour_lists.py",
            # written against mutants of the gas sample (properties/MUTATION.md, gas)
            "properties/test_gas_start_state_edges.py",
            # the lattice start's sites, walls and periodic (written against place_spheres_149)
            "properties/test_gas_lattice_sites.py",
        ],
        # 1 in 40 (141 of 5427 mutants, half of the 1-in-20 sample): about 85 min at load 8-10 on 2 cores; the
        # event-loop kernels' survivors each run the area's interpreted suite
        "sample": 40,
    },
    "narrowphase": {
        "mutate": ["engine/narrowphase/*"],
        "tests": [
            "properties/test_sat.py",
            "properties/test_gjk.py",
            "properties/test_narrowphase_primitives.py",
            "properties/test_contact.py",
            # the batched forms, contact_feature_pairs, overlap_convex_sat_pairs, time_of_impact_pairs, curve tests
            "properties/test_narrowphase_batch.py",
            # adversarial inputs (touching, flat, denormal, tied) of SAT, GJK, EPA, contact
            "properties/test_adversarial.py",
            # World: contacts and time of impact through the dispatch of the narrow phase
            "properties/test_world.py",
            # input validation of every public narrow-phase function (load_shape included)
            "properties/test_fuzz_public_api.py",
            # written against the survivors of the first narrowphase run (properties/MUTATION.md)
            "properties/test_contact_normal_edges.py",
            "properties/test_contact_io_shapes.py",
            "properties/test_epa_witnesses_and_fallback.py",
            "properties/test_epa_pairs_fallback.py",
            "properties/test_curve_jitted_errors.py",
            "properties/test_epa_vertex_touching.py",
            "properties/test_contact_axis_sharing_boxes.py",
            # EPA witnesses on their boxes when faces of A - B share the closest plane (issue 18, part 1)
            "properties/test_epa_witness_on_hull.py",
            # the closed-form contact kernels World's frame calls (plane, segment-segment, sphere-box), tested directly
            "properties/test_world_kernels.py",
            # written against the survivors of the narrowphase run on 25efdba (properties/MUTATION.md)
            "properties/test_narrowphase_argument_names.py",
            "properties/test_epa_outputs_at_every_scale.py",
            "properties/test_box_box_manifold.py",
            "properties/test_plane_contact_features.py",
            "properties/test_round_core_contacts.py",
            # written against the open survivors of the run on 25efdba and the run on 2988a19 (properties/MUTATION.md)
            "properties/test_flat_vertex_removal.py",
            "properties/test_touching_depth_sign.py",
            "properties/test_box_box_face_clipping_edges.py",
            "properties/test_sat_gaps_and_names.py",
            "properties/test_epa_touching_witnesses_and_trace.py",
            "properties/test_simplex_edge_boundaries.py",
            # a vertex on a side of the reference face is one box-box contact point
            "properties/test_box_box_points_distinct.py",
            # written against the survivors of the narrowphase run on 4a77c01 (properties/MUTATION.md)
            "properties/test_box_box_feature_kinds.py",
            # the compiled curve search (_search_jit), called directly: reached with the JIT off too
            "properties/test_curve_search_kernel.py",
            # issue 31 (level geometry) and issue 32 (face manifolds)
            "properties/test_box_box_nearly_flush.py",
            "properties/test_hull_nearly_flush.py",
            "properties/test_box_triangle.py",
            "properties/test_mesh_contacts.py",
            "properties/test_mesh_ghosts.py",
            "properties/test_mesh_rays.py",
            "properties/test_mesh_input.py",
        ],
        "sample": 64,
    },
    "bounding": {
        "mutate": ["engine/bounding/*"],
        "tests": [
            "properties/test_bounding_fits.py",
            "properties/test_bounding_overlap.py",
            "properties/test_hull.py",
            # issue 32: hulls of every full-dimensional set, convex to round-off
            "properties/test_hull_qhull_suites.py",
            "properties/test_decompose.py",
            "properties/test_bounding_argument_names.py",
            "properties/test_bounding_input_forms.py",
            "properties/test_bounding_summaries.py",
            "properties/test_rotation_matrix_inputs.py",
            # written against the run on the quickhull rewrite (properties/MUTATION.md, bounding): the batched
            # OBB check (as_obbs), and hulls that outgrow the kernel's first face capacity
            "properties/test_obb_batch_inputs.py",
            "properties/test_hull_many_faces.py",
            # Welzl's three-point ball on a near-duplicate pair (its collinear fallback)
            "properties/test_welzl_near_duplicates.py",
            # Welzl and Ritter at every magnitude (power-of-two scaling exact)
            "properties/test_sphere_scale.py",
            # Welzl's 2-, 3- and 4-point balls on their own (the flat branches it reaches only by round-off)
            "properties/test_circumsphere.py",
            # the hull at every magnitude (power-of-two scaling exact)
            "properties/test_hull_scale.py",
            # fitted spheres hold their points by sphere_contains, at every magnitude
            "properties/test_sphere_fits_contain.py",
        ],
        # 1 in 5 (about 800 mutants with hull.py, ~6 s each interpreted) does not fit a nightly job
        "sample": 20,
    },
    "world": {
        "mutate": ["engine/world/*", "engine/demo.py"],
        # plotting output (matplotlib figures, the GIF and the PNG of `colldet demo`, engine/demo_plot.py) is
        # checked by eye, not by properties, and is not in the area; the demo's physics (DemoScene,
        # engine/demo.py) is measured
        "skip": [],
        "tests": [
            "properties/test_world.py",
            "properties/test_world_input.py",
            "properties/test_world_kernels.py",
            "properties/test_world_persistence.py",
            # DemoScene.step: no body below the ground, the bounce against the closed form, seeds, energy
            "properties/test_demo_scene.py",
            # written against the survivors of the world run on 5b97b8e (properties/MUTATION.md)
            "properties/test_world_impact_edges.py",
            # written against the survivors of the world run on 7a481eb (properties/MUTATION.md)
            "properties/test_world_contact_scale.py",
            "properties/test_world_contact_radii.py",
            "properties/test_world_query_stats.py",
            "properties/test_world_repeated_ids.py",
            "properties/test_world_ground_gap.py",
            "properties/test_world_shape_argument_names.py",
        ],
        # 1 in 60 (60 of 3440 mutants; a third of the 1-in-20 sample): its surviving mutants cost 5-10 min each
        # interpreted (the World suites), so 1 in 20 does not fit a nightly job
        "sample": 60,
    },
}

#: tests (pytest node ids) not run under mutation, with the reason; see the module docstring
DESELECT: dict[str, str] = {
    "properties/test_falling.py::test_linear_drag_impacts_match_solve_ivp":
        "t_end = 1e3 s at dt <= 1e-2: 1e5 interpreted RK4 steps per example (> 6 min per run)",
    "properties/test_falling.py::test_quadratic_drag_first_impact_matches_solve_ivp":
        "t_end = 1e3 s: 1e5 interpreted RK4 steps per example",
    "properties/test_falling.py::test_step_size_does_not_move_the_impact":
        "t_end = 1e3 s, twice per example: 2e5 interpreted RK4 steps per example",
    "properties/test_broadphase_threads.py::test_threads_with_the_default_minimums_on_w1":
        "W1 at the default thread minimums (thousands of boxes, every method): 56 s for brute alone interpreted; "
        "the threads are checked bit for bit on small inputs by the file's other properties",
    "properties/test_broadphase_threads.py::test_every_threaded_box_function_on_w1_with_the_default_minimums":
        "12,000 W1 boxes, every threaded function, four thread counts: minutes interpreted; the small inputs of "
        "the file's other properties split every stage",
    "properties/test_broadphase_threads.py::test_brute_force_threads_at_the_default_minimum":
        "3,000 W1 boxes by brute force, four thread counts: 4.5e6 interpreted box tests each",
    "properties/test_broadphase_threads.py::test_sphere_pairs_every_thread_count_on_large_scenes":
        "40,000 to 60,000 spheres, four thread counts: minutes interpreted",
    "properties/test_gas_simulation.py::test_events_energy_drift_after_1e5_collisions":
        "N = 256, 1e5 collisions twice (walls, periodic): > 10 min interpreted (a run stayed on it 10 min)",
    "properties/test_gas_simulation.py::test_methods_agree_on_z_after_dt_extrapolation":
        "N = 200 over t = 62 four times, stepped down to dt = 0.005 (12,400 frames): hours interpreted",
    "properties/test_gas_simulation.py::test_speeds_relax_to_maxwell_boltzmann":
        "N = 1000 for t = 5 (> 15,000 collisions): minutes interpreted",
    "properties/test_gas_simulation.py::test_dense_fluid_from_a_lattice_up_to_eta_045":
        "N = 500 at eta = 0.45 for t = 1 (thousands of collisions): minutes interpreted",
}
