"""The trail papers' report sections, ``blazing-a-trail`` (:mod:`.blazing_a_trail`) and ``try-to-see-it-my-way`` (:mod:`.try_to_see_it_my_way`), and the helpers they share."""
