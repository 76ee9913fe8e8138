//! Contacts and queries: solver behaviour on stacks and impacts, tunnelling, recycling, the broad phase and spatial queries.

mod box3d_scenes_stand_and_settle;
mod broad_phase_hears_pose_changes;
mod collider_parts_are_never_lost_or_nan;
mod colliders_from_meshes;
mod compound_part_frames;
mod contacts_against_closed_forms;
mod contacts_end_with_the_last_collider;
mod deep_overlap_recovery;
mod energy_in_any_order;
mod every_integrator_keeps_resting_contact;
mod fast_meshes_do_not_tunnel;
mod fast_spin_stays_above_ground;
mod landing_stays_in_place;
mod mesh_contacts;
mod meshes_leave_deep_overlap_at_a_bounded_speed;
mod named_layers_and_speed_caps;
mod no_tunnelling;
mod node_contacts_never_panic;
mod prediction_follows_the_gap;
mod recycling;
mod restitution_energy;
mod restitution_threshold;
mod spatial_query;
mod spinning_rods_land_without_gaining_energy;
mod tall_stacks;
